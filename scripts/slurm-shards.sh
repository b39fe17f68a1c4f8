#!/usr/bin/env bash
# Render a scene on a Slurm cluster as a job array of shards, then merge
# them in a job that runs once every shard has succeeded.
#
#   scripts/slurm-shards.sh submit SCENE SPP SHARDS OUT [more render flags]
#
# submits two jobs: an array of SHARDS tasks, each running this script in
# `task` mode (task i renders sample indices [i*SPP/SHARDS,
# (i+1)*SPP/SHARDS) with all the cores Slurm gave it), and a job in `merge`
# mode that depends on the whole array (afterok). SCENE and OUT must be on a
# file system every node sees; shards go to OUT.shards/. Set LUEUR to the
# binary (default: `lueur` on PATH). The merged image is bit-identical to a
# single `lueur render --spp SPP` of the same scene and flags.
set -euo pipefail

mode=${1:-}
if [[ $# -lt 5 || ! $mode =~ ^(submit|task|merge)$ ]]; then
    echo "usage: $0 submit SCENE SPP SHARDS OUT [lueur render flags...]" >&2
    exit 2
fi
scene=$2 spp=$3 shards=$4 out=$5
shift 5
lueur=${LUEUR:-lueur}
dir="$out.shards"

case $mode in
submit)
    mkdir -p "$dir"
    script=$(realpath "$0")
    array=$(sbatch --parsable --job-name=lueur-shards --array="0-$((shards - 1))" \
        --output="$dir/slurm-%A_%a.log" \
        "$script" task "$scene" "$spp" "$shards" "$out" "$@")
    array=${array%%;*} # --parsable may append ";cluster"
    sbatch --parsable --job-name=lueur-merge --dependency="afterok:$array" \
        --output="$dir/slurm-merge-%j.log" \
        "$script" merge "$scene" "$spp" "$shards" "$out"
    ;;
task)
    i=${SLURM_ARRAY_TASK_ID:?task mode runs inside a Slurm array job}
    range="$((i * spp / shards))..$(((i + 1) * spp / shards))"
    "$lueur" render "$scene" --spp "$spp" --sample-range "$range" \
        --threads "${SLURM_CPUS_PER_TASK:-1}" \
        --checkpoint "$dir/shard-$range.exr" "$@"
    ;;
merge)
    "$lueur" merge "$dir"/shard-*.exr --out "$out"
    ;;
esac
