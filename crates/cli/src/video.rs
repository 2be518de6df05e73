//! A video of the hand, rendered frame by frame as a run goes, for `demo --video` and
//! `eval-stage --video`: a machine that cannot render gets a warning and no video, not a
//! failed run.

use std::path::{Path, PathBuf};

use dexcube_sim::render::{DEFAULT_CAMERA, Frame, FrameRenderer, save_video};
use dexcube_sim::{Sim, SimError};

pub struct Video {
    path: PathBuf,
    renderer: FrameRenderer,
    frames: Vec<Frame>,
    error: Option<SimError>,
}

impl Video {
    /// A video to be written to `path` (.gif, or .mp4 with ffmpeg installed) of simulations
    /// of `sim`'s scene.
    pub fn new(path: &Path, sim: &Sim) -> anyhow::Result<Video> {
        Ok(Video {
            path: path.to_path_buf(),
            renderer: FrameRenderer::new(sim, 480, 360, DEFAULT_CAMERA)?,
            frames: Vec::new(),
            error: None,
        })
    }

    /// Adds `sim` as it is now as the next frame.
    pub fn watch(&mut self, sim: &mut Sim) {
        match self.renderer.render(sim) {
            Ok(frame) => self.frames.push(frame),
            Err(e) => self.error = Some(e),
        }
    }

    /// Writes the frames at 25 per second, or warns why there are none to write.
    pub fn save(self) -> anyhow::Result<()> {
        if let Some(e) = self.error {
            eprintln!("warning: no video written to {}: {e}", self.path.display());
        } else {
            save_video(&self.frames, 25, &self.path)?;
            eprintln!(
                "wrote {} ({} frames)",
                self.path.display(),
                self.frames.len()
            );
        }
        Ok(())
    }
}
