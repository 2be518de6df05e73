//! `dexcube render`: offscreen pictures of a scene, a still or a short video of the hand
//! moving at random, for checking scenes by eye on a headless machine.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use dexcube_cube::parse_moves;
use dexcube_sim::cube::turn_face;
use dexcube_sim::render::{DEFAULT_CAMERA, FrameRenderer, save_png, save_video};
use dexcube_sim::{HAND_ACTUATORS, Scene, SceneKind, Sim};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[derive(Clone, Copy, ValueEnum)]
pub enum SceneArg {
    /// The hand with CubeRotEnv's rigid cube and its ghost target.
    Rot,
    /// The hand with LayerOpEnv's two-layer block.
    Layer,
    /// The hand with the physical 2x2x2 cube.
    Cube,
}

impl From<SceneArg> for SceneKind {
    fn from(arg: SceneArg) -> SceneKind {
        match arg {
            SceneArg::Rot => SceneKind::Rot,
            SceneArg::Layer => SceneKind::Layer,
            SceneArg::Cube => SceneKind::Cube,
        }
    }
}

/// Renders a scene offscreen to a PNG, or with --frames to a GIF (or MP4 with ffmpeg).
#[derive(Args)]
pub struct RenderArgs {
    #[arg(long, value_enum, default_value = "cube")]
    scene: SceneArg,
    /// Output file: .png for a still; .gif or .mp4 with --frames.
    #[arg(long, default_value = "frame.png")]
    out: PathBuf,
    #[arg(long, default_value_t = 640)]
    width: usize,
    #[arg(long, default_value_t = 480)]
    height: usize,
    /// Camera defined in the scene.
    #[arg(long, default_value = DEFAULT_CAMERA)]
    camera: String,
    /// Turn the physical cube's layers first (cube scene), e.g. "R U F'".
    #[arg(long)]
    scramble: Option<String>,
    /// Record this many control steps of random hand actions as a video.
    #[arg(long, default_value_t = 1)]
    frames: usize,
    /// Seed of the random actions.
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

pub fn run(args: RenderArgs) -> anyhow::Result<ExitCode> {
    if args.width > 1280 || args.height > 960 || args.width == 0 || args.height == 0 {
        bail!(
            "frames are 1x1 to 1280x960 (the scenes' offscreen buffer); got {}x{}",
            args.width,
            args.height
        );
    }
    let mut sim = Sim::new(Scene::load(args.scene.into())?);
    if let Some(moves) = &args.scramble {
        let moves = parse_moves(moves).context("cannot read --scramble")?;
        for m in moves {
            if !turn_face(&mut sim, m) {
                bail!("--scramble turns the physical cube: use it with --scene cube");
            }
        }
        sim.forward();
    }
    let mut renderer = FrameRenderer::new(&sim, args.width, args.height, &args.camera)?;
    if args.frames <= 1 {
        save_png(&renderer.render(&mut sim)?, &args.out)?;
    } else {
        let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
        let mut frames = Vec::with_capacity(args.frames);
        for _ in 0..args.frames {
            frames.push(renderer.render(&mut sim)?);
            let action: [f64; HAND_ACTUATORS] =
                std::array::from_fn(|_| rng.random_range(-1.0..=1.0));
            sim.set_action(&action);
            if let Err(e) = sim.step() {
                eprintln!("warning: {e}; resetting");
                sim.reset();
            }
        }
        // One control step is 0.04 s of simulated time: 25 frames a second is real time.
        save_video(&frames, 25, &args.out)?;
    }
    eprintln!("wrote {}", args.out.display());
    Ok(ExitCode::SUCCESS)
}
