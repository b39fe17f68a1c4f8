//! `cargo xtask codegen`: whether the compiler turned lueur's lane kernels into
//! instructions of their level's full width. Writes `docs/CODEGEN.md`; fails where a
//! level's share falls below the floor.
//!
//! AVX2's and AVX-512's lane types are vector instructions themselves
//! (`crates/sdf-math/src/lanes/x86.rs`), so a kernel's arithmetic is at full width unless
//! something in it works lane by lane outside `Lane` and LLVM's vectorizer has to put it
//! back together. That is what went wrong before them: `Wide`'s operations were loops over
//! lanes, and LLVM made lueur's kernels 0.65 full width under AVX-512 and 0.77 under
//! AVX2, while one build of the lane-resident prototype ran 2.2x slower than another of
//! the same source (docs/PERFORMANCE.md, "Paths resident in lanes: a prototype" and
//! "Explicit vector operations"). A timing sees that only as "slower", and a compiler
//! update or a kernel edit could do it again. This check reads the binary.
//!
//! Each level's kernels are the functions pulp compiles with its target features
//! (`pulp::x86::v4::V4::vectorize...` for AVX-512): every kernel is inlined whole into
//! them. In those, the packed single-precision arithmetic (add, subtract, multiply,
//! divide, square root, minimum, maximum, compare, blend) is counted by register width;
//! logic and moves are left out, since zeroing idioms and spills use narrow registers
//! whatever the kernel. The count is static: an instruction in a loop counts once. It is
//! no profile, but it is the same from run to run, needs no counters, and a split of the
//! 16-lane operations shows as a fall of the full-width share.
//!
//! x86-64 only (other targets have one vector width); needs `objdump` (binutils).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;

use anyhow::{Context, Result, bail, ensure};

use crate::memory::build_lueur;
use crate::project_root;
use crate::report::write_report;
use crate::speed::{commit, cpu_model};

/// A dispatch level with more than one vector width: its name, the part of its kernels'
/// symbol that names it, and its full-width register.
const LEVELS: [(&str, &str, &str); 2] = [
    ("AVX-512", "pulp::x86::v4::V4::vectorize", "zmm"),
    ("AVX2", "pulp::x86::v3::V3::vectorize", "ymm"),
];

/// The registers, widest first.
const WIDTHS: [&str; 3] = ["zmm", "ymm", "xmm"];

/// The packed single-precision arithmetic counted, by mnemonic stem (SSE's and VEX's);
/// compares too, whatever their predicate (`cmpltps`, `cmpnleps`...).
const ARITHMETIC: [&str; 9] = [
    "add", "sub", "mul", "div", "sqrt", "min", "max", "blendv", "blendm",
];

/// One kernel function: its address, the address of its first counted instruction, and
/// its counted instructions per register.
struct Kernel {
    address: String,
    first: Option<String>,
    counts: BTreeMap<&'static str, u64>,
}

impl Kernel {
    fn total(&self) -> u64 {
        self.counts.values().sum()
    }
}

/// The share of `counts` in register `width`.
fn share(counts: &BTreeMap<&'static str, u64>, width: &str) -> f64 {
    let total: u64 = counts.values().sum();
    counts.get(width).copied().unwrap_or(0) as f64 / total.max(1) as f64
}

pub fn run(binary: Option<&Path>, floor: f64) -> Result<()> {
    ensure!(
        (0.0..=1.0).contains(&floor),
        "--floor must be a share between 0 and 1, not {floor}"
    );
    if !cfg!(target_arch = "x86_64") {
        bail!(
            "codegen checks x86-64 builds, whose levels have several vector widths; this is {}",
            std::env::consts::ARCH
        );
    }
    let (binary, own) = match binary {
        Some(path) => (path.to_path_buf(), false),
        None => (build_lueur()?, true),
    };
    let listing = disassemble(&binary)?;
    let mut md = String::new();
    writeln!(md, "# Codegen: the lane kernels' vector widths\n")?;
    writeln!(
        md,
        "Packed single-precision arithmetic (add, subtract, multiply, divide, square root, \
         minimum, maximum, compare, blend) in the functions each dispatch level's kernels \
         are inlined into, counted by register width in the disassembly (static: an \
         instruction counts once, wherever it runs). A 16-lane operation LLVM split into \
         narrower ones shows as a fall of the full-width share. The check fails below a \
         share of {floor:.2}. Regenerate with `cargo xtask codegen`; see \
         `xtask/src/codegen.rs` for what is counted and why.\n"
    )?;
    let shown = binary.strip_prefix(project_root()).unwrap_or(&binary);
    writeln!(md, "- binary: `{}`", shown.display())?;
    writeln!(md, "- commit: {}", commit())?;
    writeln!(
        md,
        "- compiler: {} (what the counts depend on)",
        rustc_version()
    )?;
    writeln!(
        md,
        "- machine: {} (the build's instructions do not depend on it)\n",
        cpu_model()
    )?;
    writeln!(
        md,
        "| level | kernel functions | packed arithmetic | full width | zmm | ymm | xmm |"
    )?;
    writeln!(md, "|---|---|---|---|---|---|---|")?;
    let mut failures = Vec::new();
    let mut largest = String::new();
    for (level, symbol, full) in LEVELS {
        let mut kernels = kernels(&listing, symbol);
        // A build of this tree has every level; another binary (an experiment built for
        // one level) may lack some, but not all.
        if kernels.is_empty() && !own {
            writeln!(md, "| {level} | 0 | | | | | |")?;
            println!("{level}: no kernel functions");
            continue;
        }
        if kernels.is_empty() {
            bail!(
                "{} has no {level} kernel functions (no symbol containing `{symbol}`): \
                 the check cannot tell its widths (was pulp updated and its functions \
                 renamed, or the binary stripped?)",
                binary.display()
            );
        }
        let mut counts: BTreeMap<&'static str, u64> = BTreeMap::new();
        for k in &kernels {
            for (w, n) in &k.counts {
                *counts.entry(w).or_default() += n;
            }
        }
        let total: u64 = counts.values().sum();
        let at_full = share(&counts, full);
        writeln!(
            md,
            "| {level} | {} | {total} | **{at_full:.3}** | {:.3} | {:.3} | {:.3} |",
            kernels.len(),
            share(&counts, "zmm"),
            share(&counts, "ymm"),
            share(&counts, "xmm"),
        )?;
        println!("{level}: {total} packed instructions, {at_full:.3} at full width ({full})");
        if at_full < floor {
            failures.push(format!(
                "{level}: {at_full:.3} of the kernels' packed arithmetic is at full width \
                 ({full}), below the floor {floor:.2}"
            ));
        }
        kernels.sort_by_key(|k| std::cmp::Reverse(k.total()));
        kernels.truncate(LISTED);
        let names = kernel_names(&binary, &kernels);
        writeln!(largest, "\n{level}, the largest kernel functions:\n")?;
        writeln!(
            largest,
            "| kernel | address | packed arithmetic | at {full} |"
        )?;
        writeln!(largest, "|---|---|---|---|")?;
        for (k, name) in kernels.iter().zip(names) {
            let (n, at) = (k.total(), share(&k.counts, full));
            writeln!(largest, "| `{name}` | {} | {n} | {at:.3} |", k.address)?;
        }
    }
    ensure!(
        !largest.is_empty(),
        "{} has no kernel functions of any level (no symbol containing `{}`): \
         nothing to check",
        binary.display(),
        LEVELS.map(|(_, symbol, _)| symbol).join("` or `")
    );
    md.push_str(&largest);
    let called = out_of_line_intrinsics(&listing);
    writeln!(
        md,
        "\nAVX and AVX-512 intrinsics called out of line (each a call per vector operation, \
         from code compiled without their features): {}",
        if called.is_empty() {
            "none"
        } else {
            "**some**"
        }
    )?;
    for (intrinsic, callers) in &called {
        writeln!(md, "- `{intrinsic}`, from `{}`", callers.join("`, `"))?;
        failures.push(format!(
            "{intrinsic} is called out of line, from {}: code that runs a lane type's \
             operations in a function compiled without its features (run it through \
             `Lane::apart`, or inline it into the kernel)",
            callers.join(", ")
        ));
    }
    if own {
        write_report(false, "CODEGEN.md", &md)?;
    } else {
        print!("{md}");
    }
    if !failures.is_empty() {
        bail!("{}", failures.join("\n"));
    }
    Ok(())
}

/// The kernel functions listed per level.
const LISTED: usize = 8;

/// The name of the lane kernel each of `kernels` runs, from the debug information's
/// inlining chain at its first counted instruction (`addr2line`): the `LaneKernel` whose
/// `run` pulp's function calls. `?` where the binary does not say.
fn kernel_names(binary: &Path, kernels: &[Kernel]) -> Vec<String> {
    let addresses: Vec<String> = kernels
        .iter()
        .map(|k| format!("0x{}", k.first.as_deref().unwrap_or(&k.address)))
        .collect();
    let out = Command::new("addr2line")
        .args(["-a", "-f", "-i", "-C", "-e"])
        .arg(binary)
        .args(&addresses)
        .output();
    let Ok(out) = out.map(|o| String::from_utf8_lossy(&o.stdout).into_owned()) else {
        return vec!["?".into(); kernels.len()];
    };
    // Each address's block starts with the address, then function and place per inlined
    // frame, innermost first.
    let mut blocks: Vec<Vec<&str>> = Vec::new();
    for line in out.lines() {
        if line.starts_with("0x") {
            blocks.push(Vec::new());
        } else if let Some(block) = blocks.last_mut() {
            block.push(line);
        }
    }
    let mut names: Vec<String> = blocks.iter().map(|b| kernel_name(b)).collect();
    names.resize(kernels.len(), "?".into());
    names
}

/// The kernel in one address's inlining chain (innermost first): the outermost frame
/// that runs a `LaneKernel` or a `Task`, short of pulp's own.
fn kernel_name(frames: &[&str]) -> String {
    let runs = |f: &&&str| {
        (f.contains("LaneKernel>::run") || f.contains("Task>::run"))
            && !f.contains("dispatch::Run<")
    };
    let Some(frame) = frames.iter().rev().find(runs) else {
        return "?".into();
    };
    // `<path::Kernel<..> as Trait>::run` as `path::Kernel`.
    let inner = frame.trim_start_matches('<');
    let name = inner.split(" as ").next().unwrap_or(inner);
    let name = name.split('<').next().unwrap_or(name);
    name.trim_start_matches("lueur_").to_owned()
}

/// `rustc --version`, of the compiler cargo runs.
fn rustc_version() -> String {
    Command::new(std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into()))
        .arg("--version")
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map_or("unknown".into(), |o| {
            String::from_utf8_lossy(&o.stdout).trim().to_owned()
        })
}

/// `objdump -d` of `binary`, demangled.
fn disassemble(binary: &Path) -> Result<String> {
    let out = Command::new("objdump")
        .args(["-d", "--no-show-raw-insn", "-C"])
        .arg(binary)
        .output()
        .context("cannot run objdump: install binutils")?;
    ensure!(
        out.status.success(),
        "objdump -d {} failed: {}",
        binary.display(),
        String::from_utf8_lossy(&out.stderr).trim()
    );
    String::from_utf8(out.stdout).context("objdump wrote something other than UTF-8")
}

/// The functions of `listing` whose name contains `symbol`, with their counts.
fn kernels(listing: &str, symbol: &str) -> Vec<Kernel> {
    let mut kernels = Vec::new();
    let mut current: Option<Kernel> = None;
    for line in listing.lines() {
        if let Some((address, name)) = function_header(line) {
            kernels.extend(current.take());
            current = name.contains(symbol).then(|| Kernel {
                address: address.to_owned(),
                first: None,
                counts: BTreeMap::new(),
            });
            continue;
        }
        let Some(kernel) = current.as_mut() else {
            continue;
        };
        let Some((at, instruction)) = line.split_once('\t') else {
            continue;
        };
        if let Some(width) = packed_arithmetic_width(instruction.trim()) {
            *kernel.counts.entry(width).or_default() += 1;
            if kernel.first.is_none() {
                kernel.first = Some(at.trim().trim_end_matches(':').to_owned());
            }
        }
    }
    kernels.extend(current);
    kernels
}

/// The 256- and 512-bit intrinsics that `listing` holds as functions of their own, each
/// with the functions that call it. `x86.rs`'s lane types are meant to be inlined into
/// code compiled with their features; a function of theirs left out of line is compiled
/// for the baseline, which cannot inline the intrinsics and calls each one: the union of
/// 8 spheres evaluated 6 to 10x slower so (docs/PERFORMANCE.md, "Explicit vector
/// operations").
fn out_of_line_intrinsics(listing: &str) -> BTreeMap<String, Vec<String>> {
    let is_intrinsic = |name: &str| {
        name.starts_with("core::core_arch::x86")
            && (name.contains("::_mm256_") || name.contains("::_mm512_"))
    };
    let mut called: BTreeMap<String, Vec<String>> = BTreeMap::new();
    let mut current = "";
    for line in listing.lines() {
        if let Some((_, name)) = function_header(line) {
            current = name;
            continue;
        }
        let Some(target) = line.split_once('<').and_then(|(before, after)| {
            before.contains("call").then(|| after.trim_end_matches('>'))
        }) else {
            continue;
        };
        if is_intrinsic(target) && !is_intrinsic(current) {
            let callers = called.entry(target.to_owned()).or_default();
            if !callers.iter().any(|c| c == current) {
                callers.push(current.to_owned());
            }
        }
    }
    called
}

/// `0000000000012340 <name>:` as its address and name.
fn function_header(line: &str) -> Option<(&str, &str)> {
    let (address, rest) = line.split_once(' ')?;
    let name = rest.strip_prefix('<')?.strip_suffix(">:")?;
    address
        .chars()
        .all(|c| c.is_ascii_hexdigit())
        .then_some((address.trim_start_matches('0'), name))
}

/// The register width of `instruction` where it is packed single-precision arithmetic.
fn packed_arithmetic_width(instruction: &str) -> Option<&'static str> {
    let mnemonic = instruction.split_whitespace().next()?;
    let stem = mnemonic.strip_prefix('v').unwrap_or(mnemonic);
    let op = stem.strip_suffix("ps")?;
    let compare = op
        .strip_prefix("cmp")
        .is_some_and(|predicate| predicate.bytes().all(|b| b.is_ascii_lowercase()));
    let counted = compare || ARITHMETIC.contains(&op);
    if !counted {
        return None;
    }
    WIDTHS
        .into_iter()
        .find(|w| instruction.contains(w))
        .or(Some("xmm"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_packed_arithmetic_by_width() {
        assert_eq!(
            packed_arithmetic_width("vmulps %zmm1,%zmm2,%zmm3"),
            Some("zmm")
        );
        assert_eq!(
            packed_arithmetic_width("vaddps %ymm1,%ymm2,%ymm3"),
            Some("ymm")
        );
        assert_eq!(packed_arithmetic_width("mulps %xmm1,%xmm2"), Some("xmm"));
        assert_eq!(
            packed_arithmetic_width("vcmpltps %zmm1,%zmm2,%k1"),
            Some("zmm")
        );
        assert_eq!(
            packed_arithmetic_width("vblendmps %zmm1,%zmm2,%zmm3{%k1}"),
            Some("zmm")
        );
        // Scalar arithmetic, logic and moves are not counted.
        assert_eq!(packed_arithmetic_width("vmulss %xmm1,%xmm2,%xmm3"), None);
        assert_eq!(packed_arithmetic_width("vxorps %xmm0,%xmm0,%xmm0"), None);
        assert_eq!(packed_arithmetic_width("vmovups (%rax),%zmm0"), None);
        assert_eq!(packed_arithmetic_width("vaddpd %zmm1,%zmm2,%zmm3"), None);
    }

    #[test]
    fn finds_each_kernel_function() {
        let listing = "\
0000000000001000 <pulp::x86::v4::V4::vectorize::imp_fastcall>:
    1000:\tvmulps %zmm1,%zmm2,%zmm3
    1006:\tvaddps %xmm1,%xmm2,%xmm3
0000000000002000 <other>:
    2000:\tvmulps %zmm1,%zmm2,%zmm3
0000000000003000 <pulp::x86::v4::V4::vectorize::imp_fastcall>:
    3000:\tvsubps %ymm1,%ymm2,%ymm3
";
        let found = kernels(listing, "pulp::x86::v4::V4::vectorize");
        assert_eq!(found.len(), 2);
        assert_eq!(found[0].address, "1000");
        assert_eq!(found[0].counts.get("zmm"), Some(&1));
        assert_eq!(found[0].counts.get("xmm"), Some(&1));
        assert_eq!(found[1].counts.get("ymm"), Some(&1));
        assert_eq!(found[1].total(), 1);
        assert_eq!(found[0].first.as_deref(), Some("1000"));
    }

    #[test]
    fn names_the_kernel_a_chain_runs() {
        let frames = [
            "lueur_sampling::warp::sample_cosine_hemisphere_lanes",
            "/src/warp.rs:120",
            "<lueur_integrator::strategy::DrawScatters as lueur_sdf_math::lanes::dispatch::LaneKernel>::run",
            "/src/strategy.rs:300",
            "<lueur_sdf_math::lanes::dispatch::Run<K,L> as lueur_sdf_math::lanes::Task>::run",
            "/src/dispatch.rs:10",
            "<lueur_sdf_math::lanes::wide::Pulp<T> as pulp::NullaryFnOnce>::call",
            "pulp::x86::v4::V4::vectorize::imp_fastcall",
        ];
        assert_eq!(kernel_name(&frames), "integrator::strategy::DrawScatters");
        assert_eq!(kernel_name(&["main", "/src/main.rs:1"]), "?");
    }
}
