//! The point-set figures of `cargo xtask figures`: every generator of
//! `lueur_pointsets` as points and power spectrum (Figure 8), and
//! the screen-space spectrum of the rendering error with the `zsobol`
//! sampler against `independent` (Figure 10).

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;
use image::RgbImage;
use lueur::pointsets::{PointSetKind, generate, radial_power_spectrum};
use lueur::sampling::{Sampler, SamplerKind};
use lueur::scene::SceneFile;
use lueur::scene::{RenderSettings, Strategy};
use plotters::style::RGBColor;
use rayon::prelude::*;

use crate::compose::{enlarge, grid, signed_color_bar, signed_error_map, stack};
use crate::figures::save;
use crate::plot::{Axis, LinePlot, Series, decade_ticks, line_plot, scatter};
use crate::reference::{flatten, render_film};
use crate::spectrum::{ImageSpectrum, image_spectrum};

/// Sizes of the point-set figure.
pub struct PointsPlan {
    /// Points per set (a power of four, so that `sqrt(n)` is a whole
    /// frequency and every kind makes its best pattern).
    pub n: usize,
    /// Randomizations averaged in each spectrum.
    pub seeds: u64,
}

/// Width of one generator's column, in pixels.
const PANEL: u32 = 224;
/// The highest frequency of the point spectra, in units of `sqrt(n)`
/// (UTK's plots stop near there: beyond it every set looks white).
const SPECTRUM_EXTENT: usize = 3;
/// Grey of the white-noise line (`P = 1`) in the point spectra.
const WHITE_NOISE: RGBColor = RGBColor(150, 150, 150);
const INDEPENDENT: RGBColor = RGBColor(214, 39, 40);
const ZSOBOL: RGBColor = RGBColor(31, 119, 180);
/// Bound of the per-pixel luminance error in Figure 10: the display's white.
/// A few pixels per render (fireflies, and pixels on a light's edge seen
/// directly or in a mirror) have linear errors up to several times that;
/// unclamped, their energy swamps the spectrum and its comparison rests on
/// a handful of pixels. The rest of the error is below
/// it and kept linear, so unbiased (an sRGB error would be biased where the
/// noise is large, `E[srgb(x)] < srgb(E[x])`, a low-frequency pattern that
/// both samplers share). The summary prints how many pixels it changed.
const ERROR_CLAMP: f64 = 1.0;

/// Figure 8: for each kind, `plan.n` points of seed 0 above their radially
/// averaged power spectrum, averaged over `plan.seeds` seeds. Writes
/// `fig8-pointsets.png` into `dir` and returns its section of FIGURES.md.
pub fn pointsets_figure(dir: &Path, plan: &PointsPlan, flag: &str) -> Result<String> {
    let n = plan.n;
    let sqrt_n = (n as f64).sqrt().round() as usize;
    let half_size = SPECTRUM_EXTENT * sqrt_n;
    let jobs: Vec<(PointSetKind, u64)> = PointSetKind::point_sets()
        .flat_map(|k| (0..plan.seeds).map(move |s| (k, s)))
        .collect();
    let spectra = jobs
        .par_iter()
        .map(|&(kind, seed)| -> Result<Vec<f64>> {
            let points = generate(kind, n, 2, seed)?;
            Ok(radial_power_spectrum(&points, half_size)?.power)
        })
        .collect::<Result<Vec<_>>>()?;
    let mut columns = Vec::new();
    for (i, kind) in PointSetKind::point_sets().enumerate() {
        let runs = &spectra[i * plan.seeds as usize..(i + 1) * plan.seeds as usize];
        let power: Vec<f64> = (0..half_size)
            .map(|r| runs.iter().map(|p| p[r]).sum::<f64>() / runs.len() as f64)
            .collect();
        let points = generate(kind, n, 2, 0)?;
        let dots: Vec<[f64; 2]> = points.points().map(|p| [p[0], p[1]]).collect();
        let low = power[..sqrt_n / 2].iter().sum::<f64>() / (sqrt_n / 2) as f64;
        eprintln!(
            "{:>14}: mean power below sqrt(n)/2 = {low:.3} (white noise: 1)",
            kind.name()
        );
        columns.push((
            kind,
            scatter(PANEL, &dots)?,
            points_spectrum_plot(&power, sqrt_n)?,
        ));
    }
    // Two bands of six columns, each band a row of points over a row of
    // spectra: twelve columns in one row would be too wide to read.
    let mut rows = Vec::new();
    for band in columns.chunks(6) {
        rows.push(
            band.iter()
                .map(|(k, dots, _)| (k.name().to_owned(), dots.clone()))
                .collect(),
        );
        rows.push(
            band.iter()
                .map(|(_, _, plot)| (String::new(), plot.clone()))
                .collect(),
        );
    }
    let fig = grid(
        Some(&format!(
            "Fig. 8: {n} points of each generator and their power spectrum ({} seeds)",
            plan.seeds
        )),
        &rows,
    );
    let file_name = "fig8-pointsets.png";
    save(&fig, &dir.join(file_name))?;
    let mut md = String::new();
    writeln!(
        md,
        "## Figure 8: the point sets and their spectra\n\n![]({file_name})\n\n\
         Every generator of `lueur_pointsets` (`generate(kind, {n}, 2, seed)`): above, the \
         {n} points of seed 0 in the unit square; below, their radially averaged power spectrum \
         (`radial_power_spectrum` at the integer frequencies up to {half_size} = {SPECTRUM_EXTENT} \
         sqrt(n) cycles per unit, mean over seeds 0 to {}; log scale, values outside [0.01, 100] \
         drawn at the edge). The grey dashed line is white noise (P = 1): independent points follow \
         it, and so does lhs, stratified in each coordinate alone. The others have less power at low \
         frequencies, where integration error comes from: stratified and the Owen-scrambled nets \
         (halton-owen, sobol-owen, pmj02) rise smoothly to 1 near sqrt(n) = {sqrt_n}; \
         poisson-disk has a low floor and a peak just above sqrt(n), the mark of its minimum \
         distance; cmj and the unscrambled or only shifted constructions (halton, sobol, \
         sobol-xor, r2) show the spikes of their lattice-like structure. halton and sobol ignore \
         the seed, and a random shift (r2's) does not change a spectrum, so those curves are one \
         set's. Made by `cargo xtask figures{flag}`.\n",
        plan.seeds - 1
    )?;
    Ok(md)
}

/// One point set's spectrum: log power against frequency, with ticks at
/// multiples of `sqrt(n)`.
fn points_spectrum_plot(power: &[f64], sqrt_n: usize) -> Result<RgbImage> {
    let k = power.len();
    let plot = LinePlot {
        width: PANEL,
        height: 180,
        x: Axis {
            range: (0.0, k as f64),
            log: false,
            ticks: (0..=SPECTRUM_EXTENT)
                .map(|i| ((i * sqrt_n) as f64, (i * sqrt_n).to_string()))
                .collect(),
            title: "frequency".into(),
        },
        y: Axis {
            range: (1e-2, 1e2),
            log: true,
            ticks: decade_ticks(-2, 2),
            title: "power".into(),
        },
    };
    let radii = |values: &[f64]| -> Vec<(f64, f64)> {
        values
            .iter()
            .enumerate()
            .map(|(r, &p)| ((r + 1) as f64, p))
            .collect()
    };
    line_plot(
        &plot,
        &[
            Series {
                label: None,
                points: vec![(0.0, 1.0), (k as f64, 1.0)],
                color: WHITE_NOISE,
                dashed: true,
            },
            Series {
                label: None,
                points: radii(power),
                color: RGBColor(20, 20, 20),
                dashed: false,
            },
        ],
    )
}

/// Sizes of the sampler error-spectrum figure.
pub struct ErrorSpectrumPlan {
    /// Image side in pixels (the reference's).
    pub size: u32,
    pub spp: u32,
    /// Renders (seeds 1, 2, ...) averaged in each spectrum.
    pub seeds: u64,
    /// The reference's spp, for the caption.
    pub reference_spp: u32,
}

/// Figure 10: `mis` at `plan.spp` on `scenes/{scene}.toml` (`file`) with
/// the `independent` and `zsobol` samplers; each render's luminance error against `reference` (RGB, the
/// `mis` reference at the same size) and its radially averaged power
/// spectrum, averaged over seeds. Writes `fig10-zsobol-error-spectrum.png`
/// and returns its section of FIGURES.md.
pub fn zsobol_figure(
    dir: &Path,
    scene: &str,
    file: &SceneFile,
    reference: &[f32],
    plan: &ErrorSpectrumPlan,
    flag: &str,
) -> Result<String> {
    let size = plan.size as usize;
    let samplers = [SamplerKind::Independent, SamplerKind::ZSobol];
    let (results, clamped, max_error) = render_error_spectra(file, reference, plan, &samplers)?;
    let render = band_ratios(&results[0].2, &results[1].2);
    eprintln!(
        "zsobol / independent error energy, render ({} spp, {} seeds): {:.3} below {} \
         cycles per image, {:.3} in the top quarter, {:.3} overall",
        plan.spp, plan.seeds, render.low, render.low_band, render.high, render.total
    );

    // The same comparison where every pixel integrates the same smooth 2D
    // function with its first two dimensions: the case ZSobol's blue noise
    // is built for (Ahmed and Wonka 2020), as a yardstick for the render.
    let bump = integral_error_spectra(plan, &samplers);
    let integral = band_ratios(&bump[0].1, &bump[1].1);
    eprintln!(
        "zsobol / independent error energy, one 2D integral per pixel: {:.3} below {} cycles \
         per image, {:.3} in the top quarter, {:.3} overall",
        integral.low, integral.low_band, integral.high, integral.total
    );

    let fig = fig10(plan, &results, &bump)?;
    let file_name = "fig10-zsobol-error-spectrum.png";
    save(&fig, &dir.join(file_name))?;
    let mut md = String::new();
    writeln!(
        md,
        "## Figure 10: screen-space error of the zsobol sampler\n\n![]({file_name})\n\n\
         `scenes/{scene}.toml` at {s}x{s}, `--strategy mis`, {spp} spp, with `--sampler independent` and \
         `--sampler zsobol`. Above, each render's signed luminance error (0.2126 R + 0.7152 G + \
         0.0722 B of render minus the `mis` reference at {rspp} spp, in linear radiance; red below, \
         blue above, saturated at twice the RMS error of `independent`), seed 1. Below it, the \
         radially averaged power spectrum of such error images (mean removed, |DFT|^2 / pixels, \
         mean over seeds 1 to {seeds}): white noise is flat, blue noise has less power at low \
         frequencies than at high ones. The error is clamped to +-{ERROR_CLAMP} (the display's \
         white) before the transform: that changes a few pixels, fireflies and the edges of the \
         lights ({ci} of {px} for independent, {cz} for zsobol, over all seeds), whose errors (up \
         to {max_error:.1}) would otherwise outweigh all the others. zsobol's error energy below \
         {low_band} cycles per image (the lowest quarter of the frequencies) is **{rl:.2}** times \
         independent's, in the top quarter {rh:.2} times, and {rt:.2} times overall: {verdict}.\n\n\
         The bottom plot is the yardstick: the same samplers, sizes and seeds, but each pixel \
         estimates the same integral, of a smooth bump exp(-|u - (0.3, 0.6)|^2 / 0.1) over the \
         unit square, with its first two dimensions. There zsobol's error below {low_band} cycles \
         per image is **{il:.2}** times independent's, in the top quarter {ih:.2} times ({it:.2} \
         overall): blue noise, because neighbouring pixels get complementary points of one \
         Sobol' net and their errors cancel. In the render, neighbouring pixels integrate \
         different functions over many dimensions (a path of up to {depth} bounces), and that \
         correlation is lost. Made by `cargo xtask figures{flag}`.\n",
        s = plan.size,
        spp = plan.spp,
        rspp = plan.reference_spp,
        seeds = plan.seeds,
        ci = clamped[0],
        cz = clamped[1],
        px = plan.seeds * (size * size) as u64,
        low_band = render.low_band,
        rl = render.low,
        rh = render.high,
        rt = render.total,
        il = integral.low,
        ih = integral.high,
        it = integral.total,
        depth = file.settings.max_depth,
        verdict = if render.low < 0.75 * render.high {
            "in this render zsobol's error leans blue, less than in the yardstick below"
        } else {
            "in this render the error is about as white with zsobol as without"
        },
    )?;
    Ok(md)
}

/// A sampler's error image of seed 1 and its spectrum averaged over seeds.
type ErrorSpectra = (SamplerKind, Vec<f64>, ImageSpectrum);

/// Each sampler's render error against `reference`, seeds 1 to
/// `plan.seeds`: the error image of seed 1, the mean spectrum, and how many
/// pixel errors were clamped; and the largest error seen.
fn render_error_spectra(
    file: &SceneFile,
    reference: &[f32],
    plan: &ErrorSpectrumPlan,
    samplers: &[SamplerKind],
) -> Result<(Vec<ErrorSpectra>, Vec<u64>, f64)> {
    let size = plan.size as usize;
    let mut results: Vec<(SamplerKind, Vec<f64>, ImageSpectrum)> = Vec::new();
    let mut clamped = Vec::new();
    let mut max_error = 0f64;
    for &sampler in samplers {
        let mut spectra = Vec::new();
        let mut first_error = Vec::new();
        let mut clamped_pixels = 0;
        for seed in 1..=plan.seeds {
            // Seeds from 1: the reference is seed 0, and an `independent`
            // render with its seed would repeat its first samples.
            let settings = RenderSettings {
                width: plan.size,
                height: plan.size,
                spp: plan.spp,
                strategy: Strategy::Mis,
                sampler,
                seed,
                ..file.settings.clone()
            };
            let (film, _) = render_film(file, &settings)?;
            let (error, n_clamped, max) = luminance_error(&flatten(&film.mean_image()), reference);
            clamped_pixels += n_clamped;
            max_error = max_error.max(max);
            spectra.push(image_spectrum(&error, size));
            if seed == 1 {
                first_error = error;
            }
        }
        eprintln!(
            "{:>12}: {clamped_pixels} of {} pixel errors clamped to +-{ERROR_CLAMP} \
             (largest so far {max_error:.2})",
            sampler.name(),
            plan.seeds * (size * size) as u64
        );
        clamped.push(clamped_pixels);
        results.push((sampler, first_error, ImageSpectrum::mean(&spectra)));
    }
    Ok((results, clamped, max_error))
}

/// The same comparison where every pixel integrates the same smooth 2D
/// function with its first two dimensions: the case ZSobol's blue noise is
/// built for (Ahmed and Wonka 2020), as a yardstick for the render.
fn integral_error_spectra(
    plan: &ErrorSpectrumPlan,
    samplers: &[SamplerKind],
) -> Vec<(SamplerKind, ImageSpectrum)> {
    let size = plan.size as usize;
    let bump_reference = bump_integral();
    samplers
        .iter()
        .map(|&kind| {
            let spectra: Vec<ImageSpectrum> = (1..=plan.seeds)
                .map(|seed| {
                    let error =
                        pixel_integral_errors(kind, plan.size, plan.spp, seed, bump_reference);
                    image_spectrum(&error, size)
                })
                .collect();
            (kind, ImageSpectrum::mean(&spectra))
        })
        .collect()
}

/// Figure 10's image: both error maps above the two spectra.
fn fig10(
    plan: &ErrorSpectrumPlan,
    results: &[ErrorSpectra],
    bump: &[(SamplerKind, ImageSpectrum)],
) -> Result<RgbImage> {
    // Both error maps on one signed scale: twice the RMS error of the
    // independent render, so the noise's texture shows, not its outliers.
    let independent = &results[0].1;
    let rms = (independent.iter().map(|e| e * e).sum::<f64>() / independent.len() as f64)
        .sqrt()
        .max(1e-12);
    let full_scale = 2.0 * rms;
    let factor = (256 / plan.size).max(1);
    let maps: Vec<(String, RgbImage)> = results
        .iter()
        .map(|(s, e, _)| {
            let map = signed_error_map(plan.size, plan.size, e, full_scale);
            (s.to_string(), enlarge(&map, factor))
        })
        .collect();
    let maps = grid(
        Some(&format!("Fig. 10: mis, {} spp, luminance error", plan.spp)),
        &[maps],
    );
    let bar = signed_color_bar(
        plan.size * factor,
        &format!("-{full_scale:.2}"),
        &format!("+{full_scale:.2}"),
    );
    let width = maps.width() - 12;
    let render_pairs: Vec<(SamplerKind, &ImageSpectrum)> =
        results.iter().map(|(k, _, s)| (*k, s)).collect();
    let bump_pairs: Vec<(SamplerKind, &ImageSpectrum)> =
        bump.iter().map(|(k, s)| (*k, s)).collect();
    let plots = grid(
        None,
        &[
            vec![(
                "spectrum of the render's error".to_owned(),
                error_spectrum_plot(width, &render_pairs)?,
            )],
            vec![(
                "same 2D integral in every pixel".to_owned(),
                error_spectrum_plot(width, &bump_pairs)?,
            )],
        ],
    );
    Ok(stack(&[maps, bar, plots]))
}

/// Error energy of one spectrum over another's in bands of radii.
struct BandRatios {
    /// Annuli `1..=low_band` are the lowest quarter.
    low_band: usize,
    low: f64,
    /// The top quarter of the annuli.
    high: f64,
    total: f64,
}

/// `b`'s energy over `a`'s, in the lowest and highest quarters of the
/// annuli and overall.
fn band_ratios(a: &ImageSpectrum, b: &ImageSpectrum) -> BandRatios {
    let half = a.power.len();
    let quarter = half / 4;
    let band =
        |s: &ImageSpectrum, from: usize, to: usize| s.energy_up_to(to) - s.energy_up_to(from);
    BandRatios {
        low_band: quarter,
        low: band(b, 0, quarter) / band(a, 0, quarter),
        high: band(b, half - quarter, half) / band(a, half - quarter, half),
        total: band(b, 0, half) / band(a, 0, half),
    }
}

/// Log-power plot of the error spectra of the two samplers.
fn error_spectrum_plot(width: u32, spectra: &[(SamplerKind, &ImageSpectrum)]) -> Result<RgbImage> {
    let half = spectra[0].1.power.len();
    let (lo, hi) = spectra
        .iter()
        .flat_map(|(_, s)| s.power.iter().copied())
        .filter(|&p| p > 0.0)
        .fold((f64::INFINITY, 0f64), |(lo, hi), p| (lo.min(p), hi.max(p)));
    let (lo, hi) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let plot = LinePlot {
        width,
        height: 240,
        x: Axis {
            range: (0.0, half as f64),
            log: false,
            ticks: (0..=4)
                .map(|i| ((i * half / 4) as f64, (i * half / 4).to_string()))
                .collect(),
            title: "frequency (cycles per image)".into(),
        },
        y: Axis {
            range: (10f64.powi(lo), 10f64.powi(hi)),
            log: true,
            ticks: decade_ticks(lo, hi),
            title: "error power".into(),
        },
    };
    let series: Vec<Series> = spectra
        .iter()
        .map(|(kind, spectrum)| Series {
            label: Some(kind.to_string()),
            points: spectrum
                .radii()
                .zip(spectrum.power.iter().copied())
                .collect(),
            color: if *kind == SamplerKind::ZSobol {
                ZSOBOL
            } else {
                INDEPENDENT
            },
            dashed: false,
        })
        .collect();
    line_plot(&plot, &series)
}

/// The yardstick integrand: a smooth bump on the unit square.
fn bump(u: f64, v: f64) -> f64 {
    (-((u - 0.3).powi(2) + (v - 0.6).powi(2)) / 0.1).exp()
}

/// The bump's integral by the midpoint rule on a 1024 x 1024 grid (error
/// about 1e-8, far below a 4-sample estimate's).
fn bump_integral() -> f64 {
    let n = 1024;
    let h = 1.0 / f64::from(n);
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            sum += bump((f64::from(i) + 0.5) * h, (f64::from(j) + 0.5) * h);
        }
    }
    sum * h * h
}

/// Each pixel's error when it estimates the bump's integral with `spp`
/// points of dimensions 0 and 1 of `kind` (row-major, `size x size`).
fn pixel_integral_errors(
    kind: SamplerKind,
    size: u32,
    spp: u32,
    seed: u64,
    reference: f64,
) -> Vec<f64> {
    let mut sampler = Sampler::for_image(kind, seed, [size, size], spp);
    let mut errors = Vec::with_capacity((size * size) as usize);
    for y in 0..size {
        for x in 0..size {
            let mut sum = 0.0;
            for i in 0..spp {
                sampler.start_pixel_sample([x, y], i, 0);
                let u = sampler.next_2d();
                sum += bump(f64::from(u.x), f64::from(u.y));
            }
            errors.push(sum / f64::from(spp) - reference);
        }
    }
    errors
}

/// Per-pixel luminance (Rec. 709 weights) of `image - reference`, both
/// linear RGB interleaved, clamped to `+-ERROR_CLAMP`; how many pixels the
/// clamp changed, and the largest error before it.
fn luminance_error(image: &[f32], reference: &[f32]) -> (Vec<f64>, u64, f64) {
    let mut clamped = 0;
    let mut max = 0f64;
    let error = image
        .chunks_exact(3)
        .zip(reference.chunks_exact(3))
        .map(|(x, r)| {
            let d = |c: usize| f64::from(x[c]) - f64::from(r[c]);
            let y = 0.2126 * d(0) + 0.7152 * d(1) + 0.0722 * d(2);
            if y.abs() > ERROR_CLAMP {
                clamped += 1;
            }
            max = max.max(y.abs());
            y.clamp(-ERROR_CLAMP, ERROR_CLAMP)
        })
        .collect();
    (error, clamped, max)
}
