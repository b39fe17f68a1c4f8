use lueur_sampling::{Vec2, Vec3};
use lueur_stats::ChiSquareTest;
use proptest::test_runner::{Config as ProptestConfig, RngSeed};
use rand_pcg::Pcg32;
use rand_pcg::rand_core::Rng;

/// Significance level of every goodness-of-fit test.
pub const SIGNIFICANCE: f64 = 0.01;
/// Samples per goodness-of-fit test.
pub const N_SAMPLES: usize = 1_000_000;
/// Bins in `cos(theta)` and in `phi` of the directional tests.
pub const N_Z: usize = 16;
pub const N_PHI: usize = 32;
/// Midpoint-rule sub-grid per bin when integrating a pdf.
pub const SUB: usize = 32;

/// Fixed-seed uniform numbers with 24 bits, as the renderer's sampler makes
/// them (never 1.0).
pub struct Uniforms(Pcg32);

impl Uniforms {
    pub fn new(seed: u64) -> Self {
        Self(Pcg32::new(seed, 0x0a02_bdbf_7bb3_c0a7))
    }

    pub fn next_1d(&mut self) -> f32 {
        (self.0.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    pub fn next_2d(&mut self) -> Vec2 {
        let x = self.next_1d();
        let y = self.next_1d();
        Vec2::new(x, y)
    }
}

/// `N_SAMPLES` directions from `sample`, which may decline (`None` counts as
/// a failure: these configurations always have samples).
pub fn directions(seed: u64, sample: impl Fn(Vec2) -> Option<Vec3>) -> Vec<Vec3> {
    let mut u = Uniforms::new(seed);
    (0..N_SAMPLES)
        .map(|_| sample(u.next_2d()).expect("sampler declined a valid configuration"))
        .collect()
}

pub fn assert_fits(name: &str, test: ChiSquareTest) {
    eprintln!(
        "{name}: chi-square {:.1}, dof {}, p-value {:.3}",
        test.statistic, test.dof, test.p_value
    );
    assert!(
        test.accepts(SIGNIFICANCE),
        "{name}: samples do not follow the pdf: {test:?}"
    );
}

/// proptest configuration with a fixed seed and no files written.
pub fn proptest_config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        rng_seed: RngSeed::Fixed(0x005e_ed0f_1e0e),
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// Bins over the parameter square `(s, t)` of a parallelogram light seen from
/// `p`; a direction is binned where its ray meets the light's plane. Unlike
/// directional bins, these follow the light's outline exactly, so the
/// expected counts have no discontinuity inside a bin.
pub struct QuadBins {
    pub p: Vec3,
    pub corner: Vec3,
    pub edge_u: Vec3,
    pub edge_v: Vec3,
    pub n: usize,
}

impl QuadBins {
    fn st(&self, wi: Vec3) -> Option<(f64, f64)> {
        let (eu, ev) = (self.edge_u.as_dvec3(), self.edge_v.as_dvec3());
        let n_raw = eu.cross(ev);
        let wi = wi.as_dvec3();
        let denom = wi.dot(n_raw);
        if denom >= 0.0 {
            return None;
        }
        let o = self.p.as_dvec3();
        let c = self.corner.as_dvec3();
        let t = (c - o).dot(n_raw) / denom;
        let q = o + t * wi - c;
        let a2 = n_raw.length_squared();
        let s = q.cross(ev).dot(n_raw) / a2;
        let r = eu.cross(q).dot(n_raw) / a2;
        // f32 directions are rounded by ~6e-8 rad: allow that much, in the
        // parameter of each edge, plus 1e-5.
        let error = 3e-7 * t;
        let ok =
            |x: f64, edge: f64| (-1e-5 - error / edge..=1.0 + 1e-5 + error / edge).contains(&x);
        (t > 0.0 && ok(s, eu.length()) && ok(r, ev.length()))
            .then(|| (s.clamp(0.0, 1.0), r.clamp(0.0, 1.0)))
    }

    /// Observed counts, plus one last bin for directions that miss.
    pub fn histogram(&self, directions: &[Vec3]) -> Vec<f64> {
        let mut counts = vec![0.0; self.n * self.n + 1];
        for &wi in directions {
            match self.st(wi) {
                Some((s, t)) => {
                    let i = ((s * self.n as f64) as usize).min(self.n - 1);
                    let j = ((t * self.n as f64) as usize).min(self.n - 1);
                    counts[j * self.n + i] += 1.0;
                }
                None => counts[self.n * self.n] += 1.0,
            }
        }
        counts
    }

    /// Expected counts for a solid-angle `pdf`: the integral over each cell of
    /// `pdf(wi) cos(alpha) / d^2 * area`, then 0 for the miss bin.
    pub fn expected(&self, pdf: impl Fn(Vec3) -> f32, n_samples: f64) -> Vec<f64> {
        let (eu, ev) = (self.edge_u.as_dvec3(), self.edge_v.as_dvec3());
        let n_raw = eu.cross(ev);
        let area = n_raw.length();
        let normal = n_raw / area;
        let (o, c) = (self.p.as_dvec3(), self.corner.as_dvec3());
        let cells = self.n * SUB;
        let h = 1.0 / cells as f64;
        let mut counts = vec![0.0; self.n * self.n + 1];
        for j in 0..cells {
            for i in 0..cells {
                let (s, t) = ((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
                let v = c + s * eu + t * ev - o;
                let d2 = v.length_squared();
                let wi = v / d2.sqrt();
                let cos = -wi.dot(normal);
                let jacobian = cos * area / d2;
                counts[(j / SUB) * self.n + i / SUB] +=
                    f64::from(pdf(wi.as_vec3())) * jacobian * h * h * n_samples;
            }
        }
        counts
    }
}

/// Every elementary interval `[i/2^k, (i+1)/2^k) x [j/2^(m-k), (j+1)/2^(m-k))`
/// holds exactly one of the `2^m` points: a (0, m, 2)-net in base 2.
pub fn assert_0m2_net(points: &[[f64; 2]], m: u32, what: &str) {
    assert_eq!(points.len(), 1 << m, "{what}");
    for k in 0..=m {
        let (cols, rows) = (1usize << k, 1usize << (m - k));
        let mut count = vec![0u32; cols * rows];
        for p in points {
            let (cx, cy) = ((p[0] * cols as f64) as usize, (p[1] * rows as f64) as usize);
            count[cy * cols + cx] += 1;
        }
        assert!(
            count.iter().all(|&c| c == 1),
            "{what}: m = {m}, intervals {cols}x{rows} not all filled once"
        );
    }
}
