//! Hostile input for the scene parser: random and mutated TOML never makes
//! `parse_scene` panic or hang, every error names a line inside the file
//! (and a key, unless the TOML itself is malformed), and every scene that
//! parses renders a 2x2 image without a NaN or infinite sample.
//!
//! Inputs come from three generators with fixed seeds: mutations of the
//! shipped scenes (lines deleted, duplicated, swapped or inserted; numbers,
//! values, arrays and type names replaced by hostile ones; the text cut
//! short), lines of both scenes and hostile fragments shuffled together,
//! and random strings and bytes. Crashes found are kept below as named
//! regression tests.

use std::sync::mpsc;
use std::time::{Duration, Instant};

use lueur::integrator::{PreparedScene, render};
use lueur::scene::{SceneFileError, parse_scene};
use proptest::prelude::*;
use proptest::sample::{Index, select};
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

const SEEDS: [&str; 2] = [
    include_str!("../scenes/cornell-spheres.toml"),
    include_str!("../scenes/donut-mirrors.toml"),
];

/// Longest a single input may take to parse and render at 2x2, 1 spp. A
/// correct run takes milliseconds; the bound only has to catch a hang.
const TIME_LIMIT: Duration = Duration::from_secs(10);

/// Values that replace a whole value, a number or an array.
const HOSTILE_VALUES: &[&str] = &[
    "nan",
    "+nan",
    "-nan",
    "inf",
    "-inf",
    "-1",
    "0",
    "0.0",
    "-0.0",
    "1",
    "1e30",
    "-1e30",
    "1e-30",
    "1e38",
    "3.4028235e38",
    "1e39",
    "1e-45",
    "1e-300",
    "9223372036854775807",
    "-9223372036854775808",
    "99999999999999999999999",
    "4294967296",
    "16777217",
    "0x7fffffff",
    "0o777",
    "0b101",
    "1_000",
    "\"text\"",
    "\"\"",
    "'literal'",
    "\"\"\"multi\nline\"\"\"",
    "true",
    "1979-05-27T07:32:00Z",
    "[]",
    "[1.0]",
    "[1.0, 2.0]",
    "[1.0, 2.0, 3.0, 4.0]",
    "[[1.0, 2.0, 3.0]]",
    "[\"a\", \"b\", \"c\"]",
    "[nan, 0.0, 0.0]",
    "[0.0, 0.0, 0.0]",
    "[1e30, 1e30, 1e30]",
    "[-1e30, 1e30, -1e30]",
    "[1e-30, 1e-30, 1e-30]",
    "[1e-22, 0.0, 0.0]",
    "[1e-20, 1e-20, 0.0]",
    "[3e38, 3e38, 3e38]",
    "[1, 2, 3]",
    "[1.0, \"x\", 3.0]",
    "{}",
    "{ type = \"sphere\", radius = 1.0 }",
    "{ type = \"sphere\", radius = 1e-30 }",
    "{ type = \"sphere\", radius = 1e30 }",
    "{ type = \"union\", shapes = [] }",
    "{ type = \"difference\", shapes = [{ type = \"sphere\", radius = 1.0 }] }",
    "{ type = \"union\", shapes = [{ type = \"union\", shapes = [{ type = \"sphere\", radius = 0.5 }] }] }",
    "{ type = \"smooth_union\", k = 1e-30, shapes = [{ type = \"sphere\", radius = 0.5 }, { type = \"box\", half_extents = [0.4, 0.4, 0.4] }] }",
    "{ type = \"smooth_difference\", k = 1e30, shapes = [{ type = \"sphere\", radius = 0.5 }, { type = \"box\", half_extents = [0.4, 0.4, 0.4] }] }",
    "{ type = \"plane\", normal = [1e-22, 0.0, 0.0] }",
    "{ type = \"plane\", normal = [0.0, 1.0, 0.0], height = 1e30 }",
    "{ type = \"sphere\", radius = 0.5, scale = 1e-30 }",
    "{ type = \"sphere\", radius = 0.5, scale = 1e30 }",
    "{ type = \"sphere\", radius = 0.5, rotate = [1e30, 0.0, 0.0] }",
    "{ type = \"sphere\", radius = 0.5, translate = [1e30, 0.0, 0.0] }",
    "{ type = \"round_box\", half_extents = [1e-30, 1.0, 1.0], radius = 0.0 }",
    "{ type = \"capsule\", a = [0.0, 0.0, 0.0], b = [0.0, 0.0, 0.0], radius = 0.1 }",
    "{ type = \"death_star\", ra = 1.0, rb = 1e30, d = 1e-30 }",
    "{ type = \"torus\", major_radius = 1e-30, minor_radius = 1e30 }",
    "{ type = \"capped_cylinder\", radius = 1e30, half_height = 1e-30 }",
    "{ x = { y = { z = 1 } } }",
];

/// Whole lines inserted anywhere: unknown keys and tables, unknown types,
/// extreme settings, extra objects and lights.
const HOSTILE_LINES: &[&str] = &[
    "",
    "#",
    "foo = 1",
    "[unknown]",
    "[image]",
    "[render]",
    "[camera]",
    "[materials]",
    "[sky]",
    "[[objects]]",
    "[[lights]]",
    "[[camera]]",
    "objects = 3",
    "lights = [1, 2]",
    "type = \"spot\"",
    "type = \"sphere\"",
    "type = \"quad\"",
    "type = \"directional\"",
    "direction = [1e-22, 0.0, 0.0]",
    "direction = [0.0, -1.0, 0.0]",
    "irradiance = [1e30, 1e30, 1e30]",
    "radiance = [3e38, 3e38, 3e38]",
    "radiance = [1.0, 1.0, 1.0]",
    "radius = 1e-30",
    "center = [1e30, 0.0, 0.0]",
    "corner = [0.0, 0.0, 0.0]",
    "edge_u = [1e-20, 0.0, 0.0]",
    "edge_v = [0.0, 0.0, 1e-20]",
    "edge_u = [1e30, 0.0, 0.0]",
    "edge_v = [0.0, 0.0, 1e30]",
    "material = \"white\"",
    "material = \"nope\"",
    "shape = { type = \"blob\" }",
    "shape = { type = \"sphere\", radius = 0.5 }",
    "shape = { type = \"plane\", normal = [0.0, 1.0, 0.0] }",
    "shape = { type = \"sphere\", radius = 0.5, colour = 1 }",
    "white = { type = \"glass\" }",
    "black = { type = \"lambertian\", albedo = [0.0, 0.0, 0.0] }",
    "hot = { type = \"lambertian\", albedo = [1.5, 0.5, 0.5] }",
    "white = { type = \"mirror\" }",
    "spp = 1",
    "spp = 16777216",
    "spp = 16777217",
    "max_depth = 0",
    "max_depth = 10000",
    "max_steps = 1",
    "max_steps = 1048576",
    "seed = 18446744073709551615",
    "seed = -1",
    "epsilon = 1e-30",
    "epsilon = 1e30",
    "pixel_epsilon = 1e-30",
    "pixel_epsilon = 1e30",
    "strategy = \"uniform\"",
    "strategy = \"cosine\"",
    "strategy = \"light\"",
    "strategy = \"mixture\"",
    "strategy = \"mis\"",
    "strategy = \"nope\"",
    "sampler = \"sobol\"",
    "sampler = \"zsobol\"",
    "sampler = \"pmj02\"",
    "sampler = \"halton-owen\"",
    "sampler = \"nope\"",
    "quad_sampling = \"area\"",
    "quad_sampling = \"solid-angle\"",
    "quad_sampling = \"nope\"",
    "width = 65537",
    "height = 0",
    "position = [0.0, 1.0, 0.0]",
    "look_at = [0.0, 1.0, 3.0]",
    "up = [0.0, 0.0, 1.0]",
    "up = [1e-30, 0.0, 0.0]",
    "vfov = 180.0",
    "vfov = 1e-30",
    "vfov = 179.999",
    "k = 0.0",
    "[image",
    "[[objects]",
    "key = ",
    "= 1",
    "a.b.c = 1",
    "\"quoted key\" = 1",
    "x = \"unterminated",
    "\u{feff}",
    "\t \r",
    "é = 1",
];

/// Strings that replace a quoted string: every type and name the parser
/// knows, in the wrong place as often as the right one.
const NAMES: &[&str] = &[
    "sphere",
    "box",
    "round_box",
    "plane",
    "torus",
    "capped_cylinder",
    "capsule",
    "death_star",
    "union",
    "intersection",
    "difference",
    "smooth_union",
    "smooth_intersection",
    "smooth_difference",
    "lambertian",
    "mirror",
    "quad",
    "directional",
    "glass",
    "white",
    "chrome",
    "mis",
    "light",
    "sobol",
    "area",
    "",
    "\u{0}",
    "SPHERE",
];

#[derive(Clone, Debug)]
enum Mutation {
    Delete(Index),
    Duplicate(Index),
    Swap(Index, Index),
    /// Replace the n-th number of a line.
    Number(Index, Index, &'static str),
    /// Replace everything after a line's first `=`.
    Value(Index, &'static str),
    /// Replace the n-th bracketed or braced group of a line.
    Group(Index, Index, &'static str),
    Insert(Index, &'static str),
    /// Replace the n-th quoted string of a line.
    Rename(Index, Index, &'static str),
    /// Cut the whole text at a byte.
    Truncate(Index),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let idx = any::<Index>;
    let value = || select(HOSTILE_VALUES);
    prop_oneof![
        1 => idx().prop_map(Mutation::Delete),
        1 => idx().prop_map(Mutation::Duplicate),
        1 => (idx(), idx()).prop_map(|(a, b)| Mutation::Swap(a, b)),
        3 => (idx(), idx(), value()).prop_map(|(l, n, v)| Mutation::Number(l, n, v)),
        2 => (idx(), value()).prop_map(|(l, v)| Mutation::Value(l, v)),
        2 => (idx(), idx(), value()).prop_map(|(l, n, v)| Mutation::Group(l, n, v)),
        3 => (idx(), select(HOSTILE_LINES)).prop_map(|(l, v)| Mutation::Insert(l, v)),
        2 => (idx(), idx(), select(NAMES)).prop_map(|(l, n, v)| Mutation::Rename(l, n, v)),
        1 => idx().prop_map(Mutation::Truncate),
    ]
}

/// Byte ranges of the numbers of `line` (a digit, optionally signed,
/// followed by digits, dots, exponents and underscores).
fn numbers(line: &str) -> Vec<std::ops::Range<usize>> {
    let b = line.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = b[i].is_ascii_digit()
            || ((b[i] == b'-' || b[i] == b'+') && b.get(i + 1).is_some_and(u8::is_ascii_digit));
        let after_word = i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        if starts && !after_word {
            let start = i;
            i += 1;
            while i < b.len()
                && (b[i].is_ascii_digit()
                    || matches!(b[i], b'.' | b'e' | b'E' | b'_')
                    || (matches!(b[i], b'-' | b'+') && matches!(b[i - 1], b'e' | b'E')))
            {
                i += 1;
            }
            out.push(start..i);
        } else {
            i += 1;
        }
    }
    out
}

/// Byte ranges of the outermost `[...]` and `{...}` groups of `line`
/// (after its `=`, so table headers are left alone).
fn groups(line: &str) -> Vec<std::ops::Range<usize>> {
    let Some(eq) = line.find('=') else {
        return Vec::new();
    };
    let mut out = Vec::new();
    let mut depth = 0usize;
    let mut start = 0;
    for (i, c) in line.char_indices().skip_while(|&(i, _)| i <= eq) {
        match c {
            '[' | '{' => {
                if depth == 0 {
                    start = i;
                }
                depth += 1;
            }
            ']' | '}' if depth > 0 => {
                depth -= 1;
                if depth == 0 {
                    out.push(start..i + 1);
                }
            }
            _ => {}
        }
    }
    out
}

/// Byte ranges of the contents of the double-quoted strings of `line`.
fn quoted(line: &str) -> Vec<std::ops::Range<usize>> {
    let quotes: Vec<usize> = line.match_indices('"').map(|(i, _)| i).collect();
    quotes.chunks_exact(2).map(|q| q[0] + 1..q[1]).collect()
}

fn replace_nth(
    lines: &mut [String],
    l: &Index,
    n: &Index,
    find: fn(&str) -> Vec<std::ops::Range<usize>>,
    with: &str,
) {
    if lines.is_empty() {
        return;
    }
    let line = &mut lines[l.index(lines.len())];
    let ranges = find(line);
    if !ranges.is_empty() {
        let r = ranges[n.index(ranges.len())].clone();
        line.replace_range(r, with);
    }
}

fn apply(text: &str, mutations: &[Mutation]) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let mut cut = None;
    for m in mutations {
        let len = lines.len();
        match m {
            Mutation::Delete(i) if len > 0 => {
                lines.remove(i.index(len));
            }
            Mutation::Duplicate(i) if len > 0 => {
                let i = i.index(len);
                lines.insert(i, lines[i].clone());
            }
            Mutation::Swap(a, b) if len > 0 => lines.swap(a.index(len), b.index(len)),
            Mutation::Number(l, n, v) => replace_nth(&mut lines, l, n, numbers, v),
            Mutation::Group(l, n, v) => replace_nth(&mut lines, l, n, groups, v),
            Mutation::Rename(l, n, v) => replace_nth(&mut lines, l, n, quoted, v),
            Mutation::Value(l, v) if len > 0 => {
                let line = &mut lines[l.index(len)];
                if let Some(eq) = line.find('=') {
                    line.replace_range(eq + 1.., &format!(" {v}"));
                }
            }
            Mutation::Insert(i, v) => lines.insert(i.index(len + 1), (*v).to_owned()),
            Mutation::Truncate(i) => cut = Some(*i),
            _ => {}
        }
    }
    let mut text = lines.join("\n");
    text.push('\n');
    if let Some(i) = cut {
        let mut at = i.index(text.len() + 1);
        while !text.is_char_boundary(at) {
            at -= 1;
        }
        text.truncate(at);
    }
    text
}

/// Runs `f` on another thread and fails if it takes longer than
/// [`TIME_LIMIT`]; a panic in `f` is re-raised here.
fn within_time_limit<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    let handle = std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    match rx.recv_timeout(TIME_LIMIT) {
        Ok(v) => {
            handle.join().unwrap();
            v
        }
        Err(mpsc::RecvTimeoutError::Disconnected) => match handle.join() {
            Err(panic) => std::panic::resume_unwind(panic),
            Ok(()) => unreachable!("the worker neither sent nor panicked"),
        },
        Err(mpsc::RecvTimeoutError::Timeout) => {
            panic!("no answer within {TIME_LIMIT:?} (the worker is left running)")
        }
    }
}

/// The properties every input must have. Returns the outcome so that
/// regression tests can say more.
fn check(text: &str) -> Result<(), SceneFileError> {
    const FILE: &str = "fuzz.toml";
    let owned = text.to_owned();
    let start = Instant::now();
    let outcome: Result<_, SceneFileError> = within_time_limit(move || {
        let parsed = parse_scene(&owned, FILE)?;
        let mut settings = parsed.settings.clone();
        settings.width = 2;
        settings.height = 2;
        settings.spp = 1;
        let out = render(&PreparedScene::new(parsed.scene), &settings, &|_| {})
            .unwrap_or_else(|e| panic!("a scene that parsed does not render: {e}"));
        Ok(out)
    });
    let elapsed = start.elapsed();
    match outcome {
        Ok(out) => {
            assert_eq!(
                out.stats.dropped_samples, 0,
                "NaN or infinite samples ({:?})",
                out.stats
            );
            for p in out.film.pixels() {
                assert!(
                    p.mean.is_finite() && p.variance_of_mean().is_finite(),
                    "pixel {p:?}"
                );
                assert!(p.mean.min_element() >= 0.0, "negative radiance {p:?}");
            }
            assert!(elapsed < TIME_LIMIT);
            Ok(())
        }
        Err(e) => {
            let lines = text.lines().count();
            assert_eq!(e.file, FILE);
            assert!(
                e.line >= 1 && e.line <= lines + 1,
                "line {} outside 1..={} in {e:?}",
                e.line,
                lines + 1
            );
            assert!(e.column >= 1, "{e:?}");
            assert!(!e.message.is_empty(), "{e:?}");
            let syntax = e.message.starts_with("invalid TOML");
            assert!(
                syntax || !e.key.is_empty(),
                "no key for a semantic error: {e:?}"
            );
            let shown = e.to_string();
            assert!(
                shown.contains(&format!("{FILE}:{}:", e.line)),
                "rendering lacks file:line: {shown}"
            );
            Err(e)
        }
    }
}

/// A runner with a fixed seed, so that every run tries the same inputs.
fn runner(cases: u32, seed: u8) -> TestRunner {
    let config = Config {
        cases,
        failure_persistence: None,
        max_shrink_iters: 2048,
        ..Config::default()
    };
    TestRunner::new_with_rng(
        config,
        TestRng::from_seed(RngAlgorithm::ChaCha, &[seed; 32]),
    )
}

fn fuzz(cases: u32, seed: u8, inputs: impl Strategy<Value = String>) {
    runner(cases, seed)
        .run(&inputs, |text| {
            let _ = check(&text);
            Ok(())
        })
        .unwrap();
}

#[test]
fn shipped_seeds_parse_and_render() {
    for text in SEEDS {
        check(text).unwrap();
    }
}

#[test]
fn mutated_scenes_never_panic_hang_or_misplace_errors() {
    let inputs = (select(&SEEDS[..]), prop::collection::vec(mutation(), 1..5))
        .prop_map(|(seed, ms)| apply(seed, &ms));
    fuzz(1024, 1, inputs);
}

#[test]
fn lightly_mutated_scenes_mostly_parse() {
    // One mutation that keeps the file valid TOML reaches the semantic
    // checks and the renderer; count how often, so the fuzzer cannot
    // silently degenerate into testing the TOML parser only.
    let mut runner = runner(256, 2);
    let inputs = (select(&SEEDS[..]), mutation()).prop_map(|(seed, m)| apply(seed, &[m]));
    let parsed = std::cell::Cell::new(0u32);
    runner
        .run(&inputs, |text| {
            if check(&text).is_ok() {
                parsed.set(parsed.get() + 1);
            }
            Ok(())
        })
        .unwrap();
    assert!(parsed.get() >= 40, "only {} of 256 parsed", parsed.get());
}

#[test]
fn shuffled_fragments_never_panic_hang_or_misplace_errors() {
    let pool: Vec<&'static str> = SEEDS
        .iter()
        .flat_map(|s| s.lines())
        .chain(HOSTILE_LINES.iter().copied())
        .collect();
    let inputs =
        prop::collection::vec(select(pool), 0..40).prop_map(|lines| lines.join("\n") + "\n");
    fuzz(512, 3, inputs);
}

#[test]
fn random_text_never_panics() {
    fuzz(512, 4, any::<String>());
    fuzz(
        512,
        5,
        prop::collection::vec(any::<u8>(), 0..400)
            .prop_map(|b| String::from_utf8_lossy(&b).into_owned()),
    );
    // Text made of TOML's own punctuation is likelier to get past the lexer.
    fuzz(512, 6, "[\\[\\]{}=,.\"'# \n0-9a-z_+-]{0,200}");
}

// Regression tests: inputs the fuzzer found, one test each.

/// A small scene with one shape and one emitter to vary.
fn probe(strategy: &str, shape: &str, emitter: &str) -> String {
    format!(
        r#"[camera]
position = [0.0, 1.0, 3.0]
look_at = [0.0, 1.0, 0.0]
[render]
strategy = "{strategy}"
[materials]
white = {{ type = "lambertian", albedo = [1.0, 1.0, 1.0] }}
chrome = {{ type = "mirror" }}
[[objects]]
material = "white"
shape = {shape}
[[objects]]
material = "chrome"
shape = {{ type = "sphere", center = [1.0, 0.5, 0.0], radius = 0.4 }}
[[objects]]
material = "white"
shape = {{ type = "plane", normal = [0.0, 1.0, 0.0] }}
{emitter}
"#
    )
}

const STRATEGIES: [&str; 5] = ["uniform", "cosine", "light", "mixture", "mis"];
const SPHERE: &str = r#"{ type = "sphere", center = [0.0, 0.5, 0.0], radius = 0.5 }"#;
const LIGHT: &str = "[[lights]]\ntype = \"sphere\"\ncenter = [0.0, 3.0, 0.0]\nradius = 0.2\nradiance = [10.0, 10.0, 10.0]";

/// Checks that `text` is rejected at `line` and `key`, with `needle` in
/// the message.
#[track_caller]
fn rejected(text: &str, line: usize, key: &str, needle: &str) {
    let err = check(text).expect_err("the scene should be rejected");
    assert_eq!((err.line, err.key.as_str()), (line, key), "{err}");
    assert!(
        err.message.contains(needle),
        "{:?} lacks {needle:?}",
        err.message
    );
}

/// Found by hand while writing the fuzzer, then by it: a direction whose
/// squared length is subnormal passed the "non-zero" check, normalised to
/// a vector of length about 0.7, and `Scene::new` rejected the light with
/// an error on line 1 that named no key.
#[test]
fn regression_directional_light_too_short_to_normalise() {
    let light = "[[lights]]\ntype = \"directional\"\ndirection = [1e-22, -1e-22, 0.0]\nirradiance = [1.0, 1.0, 1.0]";
    rejected(
        &probe("mis", SPHERE, light),
        20,
        "lights[0].direction",
        "1.1e-19",
    );
    // The smallest accepted length normalises exactly.
    let light = light.replace("1e-22, -1e-22", "1.2e-19, 0.0");
    check(&probe("mis", SPHERE, &light)).unwrap();
}

/// A vector too long to square was called "zero".
#[test]
fn regression_huge_vector_is_not_called_zero() {
    let light = "[[lights]]\ntype = \"quad\"\ncorner = [0.0, 3.0, 0.0]\nedge_u = [1e30, 0.0, 0.0]\nedge_v = [0.0, 0.0, 1.0]\nradiance = [1.0, 1.0, 1.0]";
    rejected(
        &probe("mis", SPHERE, light),
        21,
        "lights[0].edge_u",
        "1.8e19",
    );
}

/// A sky of radiance 3e38 made uniform-strategy samples overflow to
/// infinity: 16 of 64 were dropped at 8x8, 1 spp. Emission is now capped
/// at 1e12, and the cap itself renders without a dropped sample.
#[test]
fn regression_huge_emission_is_rejected_not_dropped() {
    let sky = "[sky]\nradiance = [3e38, 3e38, 3e38]";
    rejected(&probe("uniform", SPHERE, sky), 19, "sky.radiance", "1e12");
    let light = LIGHT.replace("10.0, 10.0, 10.0", "1e13, 0.0, 0.0");
    rejected(
        &probe("mis", SPHERE, &light),
        22,
        "lights[0].radiance",
        "1e12",
    );
    for strategy in STRATEGIES {
        check(&probe(
            strategy,
            SPHERE,
            "[sky]\nradiance = [1e12, 1e12, 1e12]",
        ))
        .unwrap();
        check(&probe(
            strategy,
            SPHERE,
            &LIGHT.replace("10.0, 10.0, 10.0", "1e12, 1e12, 1e12"),
        ))
        .unwrap();
        let sun = "[[lights]]\ntype = \"directional\"\ndirection = [0.0, -1.0, 0.0]\nirradiance = [1e12, 1e12, 1e12]";
        check(&probe(strategy, SPHERE, sun)).unwrap();
    }
}

/// Extreme but accepted sizes, positions and blend radii render finite
/// images with every strategy (the fuzzer's hostile values, one at a time).
#[test]
fn extreme_accepted_values_render_finite() {
    let shapes = [
        r#"{ type = "sphere", radius = 1e30 }"#,
        r#"{ type = "sphere", radius = 1e-30 }"#,
        r#"{ type = "sphere", radius = 0.5, scale = 1e-30 }"#,
        r#"{ type = "sphere", radius = 0.5, scale = 1e30 }"#,
        r#"{ type = "sphere", radius = 0.5, translate = [1e30, 0.0, 0.0] }"#,
        r#"{ type = "sphere", radius = 0.5, rotate = [1e30, 0.0, 0.0] }"#,
        r#"{ type = "smooth_union", k = 1e-30, shapes = [{ type = "sphere", radius = 0.5 }, { type = "box", half_extents = [0.4, 0.4, 0.4] }] }"#,
        r#"{ type = "smooth_difference", k = 1e30, shapes = [{ type = "sphere", radius = 0.5 }, { type = "box", half_extents = [0.4, 0.4, 0.4] }] }"#,
        r#"{ type = "torus", major_radius = 1e-30, minor_radius = 1e30 }"#,
        r#"{ type = "capped_cylinder", radius = 1e30, half_height = 1e-30 }"#,
        r#"{ type = "death_star", ra = 1.0, rb = 1e30, d = 1e-30 }"#,
        r#"{ type = "capsule", a = [0.0, 0.0, 0.0], b = [0.0, 0.0, 0.0], radius = 0.1 }"#,
        r#"{ type = "box", half_extents = [3e38, 3e38, 3e38] }"#,
        r#"{ type = "box", center = [3e38, 0.0, 0.0], half_extents = [3e38, 3e38, 3e38] }"#,
        r#"{ type = "round_box", half_extents = [1e-30, 1.0, 1.0], radius = 0.0 }"#,
        r#"{ type = "plane", normal = [1.2e-19, 1.2e-19, 0.0] }"#,
    ];
    let lights = [
        LIGHT.replace("radius = 0.2", "radius = 1e-30"),
        LIGHT.replace("radius = 0.2", "radius = 1e30"),
        LIGHT.replace("[0.0, 3.0, 0.0]", "[1e30, 3.0, 0.0]"),
        "[[lights]]\ntype = \"quad\"\ncorner = [0.0, 3.0, 0.0]\nedge_u = [1e19, 0.0, 0.0]\nedge_v = [0.0, 0.0, 1e19]\nradiance = [1.0, 1.0, 1.0]".into(),
        "[[lights]]\ntype = \"quad\"\ncorner = [0.0, 3.0, 0.0]\nedge_u = [1e-19, 0.0, 0.0]\nedge_v = [0.0, 0.0, 1e19]\nradiance = [1.0, 1.0, 1.0]".into(),
    ];
    for strategy in STRATEGIES {
        for shape in shapes {
            check(&probe(strategy, shape, LIGHT)).unwrap();
        }
        for light in &lights {
            // Either accepted and finite, or rejected with a key (`check`).
            let _ = check(&probe(strategy, SPHERE, light));
        }
    }
}
