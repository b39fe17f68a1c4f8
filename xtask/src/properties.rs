//! `cargo xtask properties`: the workspace's property tests under seeds other than their
//! own. Every property test draws its cases from a fixed seed (so that a failure
//! reproduces anywhere and CI fails only on a change); this runs them again with
//! `PROPTEST_RNG_SEED` set to each of a range of seeds, which proptest applies over the
//! test's own, to find claims that fail on cases the fixed seeds never draw. Prints each
//! failure with its seed and proptest's minimal input, and fails if there is one. Writes
//! no report: a failure found here is fixed, and its case kept as a test of its own.

use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

use anyhow::{Context, Result, bail};

use crate::project_root;

pub fn run(first: u64, count: u64) -> Result<()> {
    let root = project_root();
    let packages = packages_with_property_tests(&root)?;
    if packages.is_empty() {
        bail!("no crate under crates/ has a `proptest!` block");
    }
    let mut args = vec!["test".to_string(), "--release".into()];
    for p in &packages {
        args.extend(["-p".into(), p.clone()]);
    }
    let cargo_test = || {
        let mut command = Command::new(env!("CARGO"));
        command.args(&args).current_dir(&root);
        command
    };
    eprintln!("properties: building the tests of {}", packages.join(", "));
    let status = cargo_test()
        .arg("--no-run")
        .status()
        .context("cannot run cargo")?;
    if !status.success() {
        bail!("cargo {} --no-run: {status}", args.join(" "));
    }
    let mut failures = Vec::new();
    for seed in first..first.saturating_add(count) {
        let out = cargo_test()
            .arg("--no-fail-fast")
            .env("PROPTEST_RNG_SEED", seed.to_string())
            .output()
            .context("cannot run cargo test")?;
        let text = String::from_utf8_lossy(&out.stdout).into_owned()
            + &String::from_utf8_lossy(&out.stderr);
        let found = failures_in(&text);
        if !out.status.success() && found.is_empty() {
            let lines: Vec<&str> = text.lines().collect();
            let tail = lines[lines.len().saturating_sub(40)..].join("\n");
            bail!("seed {seed}: cargo test failed, but no test did:\n{tail}");
        }
        eprintln!("seed {seed}: {} failing", found.len());
        failures.extend(found.into_iter().map(|f| (seed, f)));
    }
    println!(
        "`cargo xtask properties --first {first} --count {count}`: the property tests of {} \
         under PROPTEST_RNG_SEED = {first}..{}",
        packages.join(", "),
        first.saturating_add(count)
    );
    if failures.is_empty() {
        println!("no test failed");
        return Ok(());
    }
    for (seed, f) in &failures {
        println!("\nseed {seed}: {}\n  {}\n  {}", f.test, f.message, f.input);
    }
    println!(
        "\nRerun one with `PROPTEST_RNG_SEED=SEED cargo test --release -p CRATE NAME`; keep \
         its case as a test of its own once fixed."
    );
    bail!("{} failure(s)", failures.len())
}

/// One failing test in `cargo test`'s output.
#[derive(Debug, PartialEq)]
struct Failure {
    test: String,
    /// Proptest's "Test failed: ..." line, or the panic's first line.
    message: String,
    /// Proptest's "minimal failing input: ..." line, where there is one.
    input: String,
}

/// The failing tests in `text`, the output of `cargo test`, with what each printed.
fn failures_in(text: &str) -> Vec<Failure> {
    let failed: BTreeSet<&str> = text
        .lines()
        .filter_map(|l| l.strip_prefix("test ")?.strip_suffix(" ... FAILED"))
        .collect();
    let mut out = Vec::new();
    for test in failed {
        // Each failing test's output sits under its own "---- NAME stdout ----" header.
        let header = format!("---- {test} stdout ----");
        let section = text
            .split_once(&header)
            .map_or("", |(_, rest)| rest.split("\n---- ").next().unwrap_or(rest));
        let line = |prefix: &str| {
            section
                .lines()
                .find_map(|l| l.trim_start().strip_prefix(prefix).map(str::trim))
                .map(str::to_string)
        };
        // A plain test's panic: its message is the line after "panicked at FILE:LINE:COL:".
        let panic = || {
            let mut lines = section.lines().skip_while(|l| !l.contains("panicked at"));
            let at = lines
                .next()?
                .split_once("panicked at ")?
                .1
                .trim_end_matches(':');
            Some(format!("{} (at {at})", lines.next().unwrap_or("").trim()))
        };
        let message = line("Test failed: ").or_else(panic).unwrap_or_default();
        // Proptest prints the input with `{:#?}`, over many lines, up to its counts.
        let input = section
            .split_once("minimal failing input: ")
            .map(|(_, rest)| {
                let end = rest.find("\tsuccesses:").unwrap_or(rest.len());
                rest[..end].split_whitespace().collect::<Vec<_>>().join(" ")
            })
            .unwrap_or_default();
        out.push(Failure {
            test: test.to_string(),
            message,
            input,
        });
    }
    out
}

/// The packages under `crates/` whose sources or tests hold a `proptest!` block.
fn packages_with_property_tests(root: &Path) -> Result<Vec<String>> {
    let mut packages = Vec::new();
    let crates = root.join("crates");
    let mut dirs: Vec<_> = std::fs::read_dir(&crates)
        .with_context(|| format!("reading {}", crates.display()))?
        .collect::<Result<_, _>>()?;
    dirs.sort_by_key(|e| e.path());
    for dir in dirs {
        let dir = dir.path();
        if !has_property_tests(&dir)? {
            continue;
        }
        let manifest = dir.join("Cargo.toml");
        let text = std::fs::read_to_string(&manifest)
            .with_context(|| format!("reading {}", manifest.display()))?;
        let table: toml::Table =
            toml::from_str(&text).with_context(|| format!("parsing {}", manifest.display()))?;
        let name = table
            .get("package")
            .and_then(|p| p.get("name"))
            .and_then(|n| n.as_str())
            .with_context(|| format!("{}: no [package] name", manifest.display()))?;
        packages.push(name.to_string());
    }
    Ok(packages)
}

/// Whether a `.rs` file under `dir` (outside `target`) holds a `proptest!` block.
fn has_property_tests(dir: &Path) -> Result<bool> {
    for entry in std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))? {
        let path = entry?.path();
        if path.is_dir() {
            if path.file_name().is_some_and(|n| n != "target") && has_property_tests(&path)? {
                return Ok(true);
            }
        } else if path.extension().is_some_and(|e| e == "rs")
            && std::fs::read_to_string(&path)?.contains("proptest! {")
        {
            return Ok(true);
        }
    }
    Ok(false)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failures_are_read_from_cargo_test_output() {
        let text = "\
running 3 tests
test a::passes ... ok
test a::fails ... FAILED
test b::panics ... FAILED

failures:

---- a::fails stdout ----
thread 'a::fails' panicked at src/a.rs:3:1:
Test failed: no sample from outside.
minimal failing input: u = Vec2(
    0.0,
    0.0,
), radius = 0.0001
\tsuccesses: 1894

---- b::panics stdout ----
thread 'b::panics' panicked at src/b.rs:9:5:
boom

failures:
    a::fails
    b::panics
";
        assert_eq!(
            failures_in(text),
            vec![
                Failure {
                    test: "a::fails".into(),
                    message: "no sample from outside.".into(),
                    input: "u = Vec2( 0.0, 0.0, ), radius = 0.0001".into(),
                },
                Failure {
                    test: "b::panics".into(),
                    message: "boom (at src/b.rs:9:5)".into(),
                    input: String::new(),
                },
            ]
        );
        assert!(failures_in("test a ... ok\n").is_empty());
    }

    #[test]
    fn the_crates_with_property_tests_are_found() {
        let packages = packages_with_property_tests(&project_root()).unwrap();
        for expected in ["lueur-integrator", "lueur-sampling", "lueur-sdf-math"] {
            assert!(packages.iter().any(|p| p == expected), "{packages:?}");
        }
        assert!(!packages.iter().any(|p| p == "lueur-cli"), "{packages:?}");
    }
}
