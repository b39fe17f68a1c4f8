//! What a render stopped by a signal tells the user: not an error (they
//! chose to stop), but what was written and how to continue.

use std::path::PathBuf;

/// The render was stopped by a signal; what was rendered has been written.
#[derive(Debug)]
pub struct Interrupted {
    /// Samples per pixel that every pixel has.
    pub spp: u32,
    /// The interrupted pass's end and the share of pixels that reached it.
    pub unfinished: Option<(u32, f64)>,
    /// The image written, if any.
    pub out: Option<PathBuf>,
    /// The checkpoint, which holds the last complete pass.
    pub checkpoint: Option<PathBuf>,
    /// The scene file, for the command that resumes.
    pub scene: PathBuf,
}

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.spp == 0 {
            return write!(
                f,
                "interrupted before the first pass completed: nothing was written"
            );
        }
        write!(f, "interrupted at {} spp", self.spp)?;
        if let Some(out) = &self.out {
            write!(f, "; wrote {} with them", out.display())?;
            if let Some((end, share)) = self.unfinished {
                write!(
                    f,
                    " (and {end} spp in the {:.0}% of the pixels whose tiles finished the pass \
                     in progress)",
                    100.0 * share
                )?;
            }
        }
        match &self.checkpoint {
            Some(path) => write!(
                f,
                "; {} holds the {} spp: continue with `lueur render {} --resume {}`",
                path.display(),
                self.spp,
                self.scene.display(),
                path.display()
            ),
            None => write!(
                f,
                "; to be able to resume a render, give it --checkpoint FILE.exr"
            ),
        }
    }
}

impl std::error::Error for Interrupted {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_message_says_what_was_written_and_how_to_resume() {
        let i = Interrupted {
            spp: 4,
            unfinished: Some((8, 0.25)),
            out: Some("i.png".into()),
            checkpoint: Some("ck.exr".into()),
            scene: "s.toml".into(),
        };
        let m = i.to_string();
        assert!(m.starts_with("interrupted at 4 spp; wrote i.png"), "{m}");
        assert!(m.contains("8 spp in the 25%"), "{m}");
        assert!(m.contains("`lueur render s.toml --resume ck.exr`"), "{m}");
        let none = Interrupted {
            checkpoint: None,
            ..i
        };
        assert!(none.to_string().contains("give it --checkpoint"));
    }
}
