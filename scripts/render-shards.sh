#!/usr/bin/env bash
# Render a scene as SHARDS shards in parallel on this machine, then merge
# them into one image, bit-identical to a single `lueur render --spp SPP`.
#
#   scripts/render-shards.sh SCENE SPP SHARDS OUT [more `lueur render` flags]
#
# Uses GNU parallel when it is installed (one job per core), xargs -P
# otherwise. Each shard runs one thread; set LUEUR to the binary to use
# (default: `lueur` on PATH). Shards are kept in OUT.shards/ so that a failed
# run can be finished by hand, and removed after a successful merge.
set -euo pipefail

if [[ $# -lt 4 ]]; then
    echo "usage: $0 SCENE SPP SHARDS OUT [lueur render flags...]" >&2
    exit 2
fi
scene=$1 spp=$2 shards=$3 out=$4
shift 4
lueur=${LUEUR:-lueur}
dir="$out.shards"
mkdir -p "$dir"

# Shard i renders sample indices [i*SPP/SHARDS, (i+1)*SPP/SHARDS).
ranges() {
    for ((i = 0; i < shards; i++)); do
        echo "$((i * spp / shards))..$(((i + 1) * spp / shards))"
    done
}

if command -v parallel >/dev/null 2>&1; then
    ranges | parallel -q --halt now,fail=1 \
        "$lueur" render "$scene" --spp "$spp" --sample-range {} --threads 1 \
        --checkpoint "$dir/shard-{}.exr" "$@"
else
    ranges | xargs -P "$(nproc)" -I{} \
        "$lueur" render "$scene" --spp "$spp" --sample-range {} --threads 1 \
        --checkpoint "$dir/shard-{}.exr" "$@"
fi

"$lueur" merge "$dir"/shard-*.exr --out "$out"
rm -r "$dir"
