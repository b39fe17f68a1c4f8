//! `lueur render`: everything is checked and set up before the first sample
//! ([`prepare`]), the passes run with their per-pass duties (checkpoint,
//! reference, partial image: [`render_passes`]), then the image is written
//! and the render's end reported ([`finish`]).

use std::ops::Range;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use lueur_integrator::SimdLevel;
use lueur_integrator::{Execution, Film, PixelBounds, PreparedScene, RenderOutput};
use lueur_scene::parse_scene_with;
use lueur_scene::{Marching, RenderSettings};

use crate::fingerprint::Fingerprint;
use crate::interrupt::Interrupted;
use crate::output::Format;
use crate::progressive::{self, Limits, Stop};
use crate::{
    BadInput, RenderArgs, bar, checkpoint, crop, output, partial, positive, provenance, reference,
    resume, summary, validate,
};

/// A render checked and set up, before its first sample.
struct Job {
    /// The scene file's name and text (for provenance and checkpoints).
    file: String,
    text: String,
    scene: PreparedScene,
    settings: RenderSettings,
    /// The sample indices to render (a shard's, or `0..spp`).
    range: Range<u32>,
    out: Option<PathBuf>,
    format: Option<Format>,
    /// The pixels rendered: the crop, or the whole image.
    region: PixelBounds,
    limits: Limits,
    reference: Option<reference::Reference>,
    fingerprint: String,
}

/// Runs `lueur render`.
pub fn run(mut args: RenderArgs) -> Result<()> {
    let (mut job, film) = prepare(&mut args)?;
    let (output, stop) = render_passes(&args, &mut job, film)?;
    finish(&args, &job, &output, stop)
}

/// Reads, overrides and checks everything a render needs, refusing bad
/// input (exit 2) before any sample is drawn; restores a checkpoint's
/// settings into `args` when resuming. Gives the job and the film to extend.
fn prepare(args: &mut RenderArgs) -> Result<(Job, Film)> {
    let file = args.scene.display().to_string();
    let text = std::fs::read_to_string(&args.scene)
        .map_err(|e| BadInput(format!("cannot read scene file {file}: {e}")))?;
    let resumed = match args.resume.clone() {
        Some(path) => {
            validate::input("--resume", &path)?;
            Some(resume::restore(&path, args)?)
        }
        None => None,
    };
    let overrides: Vec<&str> = args.set.iter().map(String::as_str).collect();
    let parsed = parse_scene_with(&text, &file, &overrides)?;
    let settings = apply_flags(parsed.settings, args)?;
    let range = render_range(args, &settings)?;
    let (out, format) = validate::render_outputs(args)?;
    let bounds = crop::bounds(
        args.crop_window.as_deref(),
        args.pixel_bounds.as_deref(),
        settings.width,
        settings.height,
    )?;
    let limits = render_limits(args, out.is_some())?;
    let region = bounds.unwrap_or(PixelBounds::whole(settings.width, settings.height));
    let reference = reference_for(args, [region.width(), region.height()])?;
    progressive::install_signal_handler()?;

    let fingerprint = Fingerprint::of(&settings, bounds, args.sample_range.as_ref(), &args.set);
    let film = match (&args.resume, &resumed) {
        (Some(path), Some(resumed)) => {
            resume::load(path, resumed, &text, &fingerprint, settings.sampler, &range)?
        }
        _ => Film::starting_at(region.width(), region.height(), range.start),
    };
    // Without a checkpoint nobody will extend the film: it can keep one
    // image instead of one per dyadic block (two at 24 spp, three at 100).
    let film = match args.checkpoint {
        Some(_) => film,
        None => film.sealed_at(range.end),
    };
    let job = Job {
        file,
        text,
        scene: PreparedScene::new(parsed.scene).with_execution(execution(args)?),
        settings,
        range,
        out,
        format,
        region,
        limits,
        reference,
        fingerprint: fingerprint.to_string(),
    };
    Ok((job, film))
}

/// Runs the passes on `--threads` workers with the progress bar, saving the
/// checkpoint, comparing with the reference and writing the partial image
/// after each.
fn render_passes(args: &RenderArgs, job: &mut Job, film: Film) -> Result<(RenderOutput, Stop)> {
    let pixels = u64::from(job.region.width()) * u64::from(job.region.height());
    let asked = job.range.end - job.range.start;
    let bar = bar::Bar::new(
        pixels * u64::from(asked),
        pixels * u64::from(film.spp().min(asked)),
        job.limits.time,
        args.quiet,
    );
    let progress = |n: u64| bar.add(n);
    let mut partial = match (job.limits.pass_seconds, &job.out, job.format) {
        (Some(every), Some(out), Some(format)) => Some(partial::Partial::new(
            every,
            out.clone(),
            format,
            args.exposure,
        )),
        _ => None,
    };
    let started = Instant::now();
    let Job {
        file,
        text,
        scene,
        settings,
        range,
        region,
        limits,
        fingerprint,
        reference,
        ..
    } = job;
    let mut after_pass = |film: &Film| {
        if let Some(r) = reference.as_mut() {
            let e = r.after_pass(film)?;
            bar::message(&format!(
                "{} spp: MSE {:.4e} against the reference, estimated {:.4e}; relative MSE {:.4e}",
                film.spp(),
                e.mse,
                e.estimated_mse,
                e.rel_mse
            ));
        }
        if let Some(path) = &args.checkpoint {
            checkpoint::save(path, film, text, fingerprint)
                .with_context(|| format!("cannot write checkpoint {}", path.display()))?;
        }
        partial.as_mut().map_or(Ok(()), |p| {
            p.after_pass(film, || {
                let seconds = started.elapsed().as_secs_f64();
                provenance::of_render(
                    file,
                    text,
                    settings,
                    film.samples(),
                    seconds,
                    film.relative_error(),
                )
            })
        })
    };
    let (settings, region, end, limits) = (&*settings, *region, range.end, *limits);
    let run = || {
        progressive::render(
            scene,
            settings,
            region,
            film,
            end,
            limits,
            &progress,
            &mut after_pass,
        )
    };
    let (output, stop) = match args.threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .context("cannot start the worker threads")?
            .install(run),
        None => run(),
    }?;
    bar.finish();
    Ok((output, stop))
}

/// Writes the image with its provenance and reports how the render ended;
/// an interrupt is reported as such (exit 130) once everything is written.
fn finish(args: &RenderArgs, job: &Job, output: &RenderOutput, stop: Stop) -> Result<()> {
    let interrupted = || Interrupted {
        spp: output.film.spp(),
        unfinished: output
            .film
            .unfinished_pass()
            .map(|(samples, share)| (samples.end - output.film.samples().start, share)),
        out: job.out.clone().filter(|_| output.film.spp() > 0),
        checkpoint: args.checkpoint.clone(),
        scene: args.scene.clone(),
    };
    if output.film.spp() == 0 {
        // Interrupted during the first pass: a partly black image is of no
        // use to anyone.
        return Err(interrupted().into());
    }
    if let (Some(out), Some(format)) = (&job.out, job.format) {
        let provenance = provenance::of_render(
            &job.file,
            &job.text,
            &job.settings,
            output.film.samples(),
            output.stats.elapsed.as_secs_f64(),
            output.film.relative_error(),
        );
        output::write_image(out, format, &output.film, args.exposure, &provenance)
            .with_context(|| format!("cannot write {}", out.display()))?;
    }
    summary::report(
        args,
        &job.settings,
        output,
        stop,
        job.out.as_deref(),
        job.range.end - job.range.start,
        &job.limits,
    );
    if stop == Stop::Interrupted {
        return Err(interrupted().into());
    }
    Ok(())
}

/// The converged image `--reference` names, checked against the size of what
/// is rendered (the crop's, where there is one) before the first sample.
fn reference_for(
    args: &RenderArgs,
    [width, height]: [u32; 2],
) -> Result<Option<reference::Reference>> {
    args.reference
        .as_deref()
        .map(|p| reference::load(p, width, height, args.reference_out.clone()))
        .transpose()
        .map_err(|e| BadInput(format!("{e:#}")).into())
}

/// The sample indices to render: a shard's (`--sample-range`, which needs
/// a checkpoint to save it in), or all of `0..spp`.
/// How the render runs: `--simd`, checked against what this CPU has, `--wave` and
/// `--no-lane-wave`.
fn execution(args: &RenderArgs) -> Result<Execution> {
    let mut execution = Execution {
        lane_wave: !args.no_lane_wave,
        ..Execution::default()
    };
    match args.wave {
        Some(0) => bail!(BadInput("--wave must be at least 1".into())),
        Some(wave) => execution.wave = wave,
        None => {}
    }
    if let Some(name) = &args.simd {
        let available: Vec<&str> = SimdLevel::available().iter().map(|l| l.name()).collect();
        let level = SimdLevel::from_name(name).ok_or_else(|| {
            let known: Vec<&str> = SimdLevel::ALL.iter().map(|l| l.name()).collect();
            BadInput(format!(
                "--simd {name}: not a level; the levels are {}",
                known.join(", ")
            ))
        })?;
        if !level.is_available() {
            bail!(BadInput(format!(
                "--simd {name}: this CPU cannot run it; it can run {}",
                available.join(", ")
            )));
        }
        execution.simd = level;
    }
    Ok(execution)
}

/// When to stop or cut passes short: --time, --target-error,
/// --partial-every (which needs an image to write, `has_out`); and whether the film is
/// read after every pass (--target-error, --reference, --checkpoint).
fn render_limits(args: &RenderArgs, has_out: bool) -> Result<progressive::Limits> {
    if args.threads == Some(0) {
        bail!(BadInput("--threads must be at least 1".into()));
    }
    let target_error = positive(args.target_error, "--target-error")?;
    let limits = progressive::Limits {
        time: positive(args.time, "--time")?,
        target_error,
        pass_seconds: positive(args.partial_every, "--partial-every")?,
        watched: target_error.is_some() || args.reference.is_some() || args.checkpoint.is_some(),
    };
    if limits.pass_seconds.is_some() && !has_out {
        bail!(BadInput(
            "--partial-every writes the output image: give it with --out".into()
        ));
    }
    Ok(limits)
}

fn render_range(args: &RenderArgs, settings: &RenderSettings) -> Result<Range<u32>> {
    Ok(match &args.sample_range {
        Some(r) if r.end > settings.spp => {
            return Err(BadInput(format!(
                "--sample-range {}..{} ends past the render's {} spp (set the total with --spp)",
                r.start, r.end, settings.spp
            ))
            .into());
        }
        Some(_) if args.checkpoint.is_none() => {
            return Err(BadInput(
                "--sample-range renders a shard: save it with --checkpoint FILE, for `lueur merge`"
                    .into(),
            )
            .into());
        }
        Some(r) => r.clone(),
        None => 0..settings.spp,
    })
}

fn apply_flags(mut s: RenderSettings, a: &RenderArgs) -> Result<RenderSettings> {
    if a.naive {
        s.marching = Marching::Naive;
    }
    if let Some(v) = a.spp {
        s.spp = v;
    }
    if let Some(v) = a.strategy {
        s.strategy = v;
    }
    if let Some(v) = a.sampler {
        s.sampler = v;
    }
    if let Some(v) = a.seed {
        s.seed = v;
    }
    if let Some(v) = a.max_depth {
        s.max_depth = v;
    }
    if let Some(v) = a.roulette_depth {
        s.roulette_depth = v;
    }
    if let Some(v) = a.width {
        s.width = v;
    }
    if let Some(v) = a.height {
        s.height = v;
    }
    if let Some(v) = a.replicates {
        s.replicates = Some(v);
    }
    if !a.exposure.is_finite() {
        bail!(BadInput("--exposure must be finite".into()));
    }
    s.validate().map_err(|e| match e {
        lueur_scene::RenderError::Replicates(why) => match a.replicates {
            Some(_) => BadInput(format!("--replicates: {why}")),
            None => BadInput(format!(
                "render.replicates of {}: {why} (override it with --replicates)",
                a.scene.display()
            )),
        },
        e => BadInput(e.to_string()),
    })?;
    Ok(s)
}
