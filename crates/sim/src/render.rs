//! Offscreen pictures of a scene: frames through MuJoCo's renderer on an EGL context (Mesa's
//! software device on a headless machine), saved as PNG, animated GIF, or MP4 via ffmpeg
//! when it is installed. Files are written to a temporary name and renamed, so a killed run
//! never leaves half a file. A renderer belongs to the thread that built it.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use mujoco_rs::prelude::*;
use mujoco_rs::renderer::MjRenderer;
use mujoco_rs::wrappers::mj_model::MjtObjBase;

use crate::error::SimError;
use crate::sim::Sim;

/// The camera every scene defines, looking at the hand and the cube.
pub const DEFAULT_CAMERA: &str = "closeup";

/// One RGB picture, rows top to bottom, 3 bytes a pixel.
#[derive(Clone, Debug)]
pub struct Frame {
    pub width: usize,
    pub height: usize,
    pub rgb: Vec<u8>,
}

pub struct FrameRenderer {
    renderer: MjRenderer,
    width: usize,
    height: usize,
}

impl FrameRenderer {
    /// A renderer for `sim`'s scene through the named camera. Frames may be at most the
    /// scene's offscreen buffer, 1280x960.
    pub fn new(
        sim: &Sim,
        width: usize,
        height: usize,
        camera: &str,
    ) -> Result<FrameRenderer, SimError> {
        let model = sim.scene().model();
        let camera_id = model
            .name_to_id(MjtObjBase::mjOBJ_CAMERA, camera)
            .ok_or_else(|| SimError::MissingElement {
                path: sim.scene().path().to_path_buf(),
                kind: "camera",
                name: camera.to_string(),
            })?;
        let renderer = MjRenderer::builder()
            .width(width as u32)
            .height(height as u32)
            .num_visual_internal_geom(400)
            .camera(MjvCamera::new_fixed(camera_id))
            .build(model)
            .map_err(|e| SimError::Render {
                message: e.to_string(),
            })?;
        Ok(FrameRenderer {
            renderer,
            width,
            height,
        })
    }

    /// The frames' (width, height).
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Renders the simulation as it is now.
    pub fn render(&mut self, sim: &mut Sim) -> Result<Frame, SimError> {
        let fail = |e: mujoco_rs::renderer::RendererError| SimError::Render {
            message: e.to_string(),
        };
        self.renderer.sync_data(sim.data_mut()).map_err(fail)?;
        self.renderer.render().map_err(fail)?;
        // mujoco-rs has already turned OpenGL's bottom-up rows top-down.
        let rgb = self.renderer.rgb_flat().ok_or_else(|| SimError::Render {
            message: "no RGB buffer".into(),
        })?;
        Ok(Frame {
            width: self.width,
            height: self.height,
            rgb: rgb.to_vec(),
        })
    }
}

/// Writes `path` through a temporary file in the same folder, renamed into place at the end.
fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), String>,
) -> Result<(), SimError> {
    let fail = |message: String| SimError::Write {
        path: path.to_path_buf(),
        message,
    };
    let mut temporary = PathBuf::from(path);
    temporary.as_mut_os_string().push(".tmp");
    let file = File::create(&temporary).map_err(|e| fail(e.to_string()))?;
    let mut out = BufWriter::new(file);
    write(&mut out).map_err(fail)?;
    out.flush().map_err(|e| fail(e.to_string()))?;
    drop(out);
    std::fs::rename(&temporary, path).map_err(|e| fail(e.to_string()))
}

/// Saves a frame as a compressed PNG.
pub fn save_png(frame: &Frame, path: &Path) -> Result<(), SimError> {
    write_atomically(path, |out| {
        let mut encoder = png::Encoder::new(out, frame.width as u32, frame.height as u32);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::Balanced);
        let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
        writer
            .write_image_data(&frame.rgb)
            .map_err(|e| e.to_string())
    })
}

/// Saves frames as a video: MP4 through ffmpeg for a `.mp4` path (ffmpeg must be installed),
/// an animated GIF otherwise.
pub fn save_video(frames: &[Frame], fps: u32, path: &Path) -> Result<(), SimError> {
    let fail = |message: String| SimError::Write {
        path: path.to_path_buf(),
        message,
    };
    let first = frames
        .first()
        .ok_or_else(|| fail("no frames to write".into()))?;
    if path.extension().is_some_and(|e| e == "mp4") {
        return save_mp4(frames, first, fps, path);
    }
    write_atomically(path, |out| {
        let mut encoder = gif::Encoder::new(out, first.width as u16, first.height as u16, &[])
            .map_err(|e| e.to_string())?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(|e| e.to_string())?;
        for frame in frames {
            let mut gif_frame =
                gif::Frame::from_rgb_speed(frame.width as u16, frame.height as u16, &frame.rgb, 10);
            gif_frame.delay = (100 / fps.max(1)) as u16;
            encoder.write_frame(&gif_frame).map_err(|e| e.to_string())?;
        }
        Ok(())
    })
}

fn save_mp4(frames: &[Frame], first: &Frame, fps: u32, path: &Path) -> Result<(), SimError> {
    let fail = |message: String| SimError::Write {
        path: path.to_path_buf(),
        message,
    };
    let mut temporary = PathBuf::from(path);
    temporary.set_extension("tmp.mp4");
    let mut ffmpeg = Command::new("ffmpeg")
        .args([
            "-loglevel",
            "error",
            "-y",
            "-f",
            "rawvideo",
            "-pix_fmt",
            "rgb24",
        ])
        .args([
            "-s",
            &format!("{}x{}", first.width, first.height),
            "-r",
            &fps.to_string(),
        ])
        .args([
            "-i",
            "-",
            "-pix_fmt",
            "yuv420p",
            "-vf",
            "pad=ceil(iw/2)*2:ceil(ih/2)*2",
        ])
        .arg(&temporary)
        .stdin(Stdio::piped())
        .spawn()
        .map_err(|e| {
            fail(format!(
                "ffmpeg is needed for .mp4 ({e}); install it, or write a .gif"
            ))
        })?;
    let mut stdin = ffmpeg
        .stdin
        .take()
        .ok_or_else(|| fail("ffmpeg has no input".into()))?;
    for frame in frames {
        stdin
            .write_all(&frame.rgb)
            .map_err(|e| fail(e.to_string()))?;
    }
    drop(stdin);
    let status = ffmpeg.wait().map_err(|e| fail(e.to_string()))?;
    if !status.success() {
        return Err(fail(format!("ffmpeg failed ({status})")));
    }
    std::fs::rename(&temporary, path).map_err(|e| fail(e.to_string()))
}
