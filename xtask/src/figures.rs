//! `cargo xtask figures`: the report's images, regenerated.

use anyhow::Result;
use lueur::integrator::{RenderSettings, Strategy};

use crate::{load_scene, project_root, render_with_bar, save_png};

/// The shipped scenes, in the order of the report's figures.
pub const SCENES: [&str; 3] = ["death-star", "donut-mirrors", "cornell-spheres"];

pub fn run(quick: bool) -> Result<()> {
    let dir = project_root().join("docs").join("figures");
    std::fs::create_dir_all(&dir)?;
    let shrink = |s: &mut RenderSettings| {
        if quick {
            s.width /= 4;
            s.height /= 4;
            s.spp = s.spp.min(8);
        }
    };
    for name in SCENES {
        let file = load_scene(name)?;
        let mut settings = file.settings.clone();
        shrink(&mut settings);
        let film = render_with_bar(&file.scene, &settings, name)?;
        save_png(&film, &dir.join(format!("{name}.png")))?;
    }
    // Figures 3 to 6: each strategy at 4 and 128 spp on the donut.
    let file = load_scene("donut-mirrors")?;
    for strategy in [
        Strategy::Uniform,
        Strategy::Light,
        Strategy::Mixture,
        Strategy::Mis,
    ] {
        for spp in [4, 128] {
            let mut settings = RenderSettings {
                spp,
                strategy,
                ..file.settings.clone()
            };
            shrink(&mut settings);
            let label = format!("donut {strategy} {spp} spp");
            let film = render_with_bar(&file.scene, &settings, &label)?;
            save_png(&film, &dir.join(format!("donut-{strategy}-{spp}spp.png")))?;
        }
    }
    eprintln!("figures written to {}", dir.display());
    Ok(())
}
