//! Poisson-disk points in the unit square, by relaxation dart throwing on
//! the torus.
//!
//! McCool and Fiume 1992, "Hierarchical Poisson disk sampling
//! distributions", Graphics Interface: darts are thrown uniformly and kept
//! when no kept point lies within the current radius; after a run of
//! rejections the radius shrinks, so exactly `n` points are produced with a
//! radius close to the largest the run allows. Distances are toroidal (the
//! square wraps around), so the set tiles and has no boundary effect, the
//! convention of blue-noise spectra (Ulichney 1988, "Dithering with blue
//! noise", Proc. IEEE 76(1)).

use rand_pcg::Pcg32;
use rand_pcg::rand_core::Rng;

use super::hash::{hash2, u64_to_unit};

/// Rejections in a row before the radius shrinks.
const MAX_FAILURES: u32 = 200;
/// Factor applied to the radius after `MAX_FAILURES` rejections.
const SHRINK: f64 = 0.97;

/// The radius of the densest packing of `n` disks on the unit torus, the
/// hexagonal one: `n` hexagons of area `sqrt(3)/2 r^2` tile the square.
pub fn poisson_disk_max_radius(n: usize) -> f64 {
    (2.0 / (3.0f64.sqrt() * n as f64)).sqrt()
}

/// Distance on the unit torus between two points of `[0, 1)^2`.
pub fn toroidal_distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    let wrap = |d: f64| {
        let d = d.abs();
        d.min(1.0 - d)
    };
    wrap(a[0] - b[0]).hypot(wrap(a[1] - b[1]))
}

/// `n` points of `[0, 1)^2`, pairwise at toroidal distance at least the
/// final radius of the relaxation.
pub(crate) fn poisson_disk_2d(n: usize, seed: u64) -> Vec<[f64; 2]> {
    let mut points: Vec<[f64; 2]> = Vec::with_capacity(n);
    if n == 0 {
        return points;
    }
    let r_max = poisson_disk_max_radius(n);
    // Cells of side <= r_max / 2: a disk of radius r <= r_max reaches at most
    // 2 cells away.
    let side = ((2.0 / r_max).ceil() as usize).max(1);
    let cell_of = |p: [f64; 2]| {
        let cx = ((p[0] * side as f64) as usize).min(side - 1);
        let cy = ((p[1] * side as f64) as usize).min(side - 1);
        (cx, cy)
    };
    let mut grid: Vec<Vec<u32>> = vec![Vec::new(); side * side];
    let state = hash2(seed, 0x706f_6973);
    let mut rng = Pcg32::new(state, hash2(state, 1));
    // Start a little below the packing radius: random packings jam near
    // 0.75 r_max, so no time is spent at radii that cannot be filled.
    let mut r = 0.9 * r_max;
    let mut failures = 0;
    while points.len() < n {
        let p = [u64_to_unit(rng.next_u64()), u64_to_unit(rng.next_u64())];
        let (cx, cy) = cell_of(p);
        let reach = ((r * side as f64).ceil() as usize).min(side / 2);
        let span = (2 * reach + 1).min(side);
        let mut free = true;
        'search: for dy in 0..span {
            let y = (cy + side + dy - reach) % side;
            for dx in 0..span {
                let x = (cx + side + dx - reach) % side;
                for &q in &grid[y * side + x] {
                    if toroidal_distance(p, points[q as usize]) < r {
                        free = false;
                        break 'search;
                    }
                }
            }
        }
        if free {
            grid[cy * side + cx].push(points.len() as u32);
            points.push(p);
            failures = 0;
        } else {
            failures += 1;
            if failures == MAX_FAILURES {
                r *= SHRINK;
                failures = 0;
            }
        }
    }
    points
}
