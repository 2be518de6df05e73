//! Where Stage 1's drops start from: for the starts the operator recorded
//! (`dexcube eval --record-starts`), the turn Stage 1 was asked for, told by the cube axis that
//! must end up vertical (in pair mode either end of it may point up). It prints how many starts,
//! and how many of them the recorded policy dropped the cube from, by how far that axis
//! leans from vertical at the start and, for the quarter flips, by the compass direction it
//! points in across the palm (azimuth in the world frame; the thumb lies towards -x and the
//! fingertips towards -y; before session 38 this said the fingertips lay towards -x), and
//! by how far the cube itself leans, whichever face it rests on.
//!
//! `cargo run --release -p dexcube-operator --example stage1_start_geometry -- STARTS...`

use std::path::Path;

use dexcube_env::{CubeRotEnv, RotGoal, RotMode, SimulatedEnv};
use dexcube_sim::cube::{face_normal, face_toward};
use dexcube_sim::rotation::{Quat, rotate};
use dexcube_sim::{Scene, SceneKind};

const UP: [f64; 3] = [0.0, 0.0, 1.0];

const TILT_BINS: [(f64, f64); 6] = [
    (0.0, 45.0),
    (45.0, 70.0),
    (70.0, 80.0),
    (80.0, 85.0),
    (85.0, 90.1),
    (0.0, 90.1),
];
const LEAN_BINS: [(f64, f64); 5] = [
    (0.0, 5.0),
    (5.0, 10.0),
    (10.0, 20.0),
    (20.0, 35.0),
    (35.0, 55.0),
];
/// The quarter flips among [`TILT_BINS`].
const FLIP_BINS: [(f64, f64); 4] = [(45.0, 70.0), (70.0, 80.0), (80.0, 85.0), (85.0, 90.1)];

/// One start: how far the axis to bring up leans from vertical, its azimuth, in degrees, and
/// whether the recorded policy dropped the cube from there.
struct Start {
    /// How far the cube's most nearly vertical axis leans, whichever face it rests on.
    lean: f64,
    tilt: f64,
    azimuth: f64,
    dropped: bool,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() {
        return Err("usage: stage1_start_geometry STARTS...".into());
    }
    let mut env =
        CubeRotEnv::with_scene(Scene::load(SceneKind::Cube)?, RotGoal::paper(RotMode::Pair));
    let mut starts = Vec::new();
    for path in &paths {
        let (recorded, _) = dexcube_rl::start_file::load_starts(Path::new(path))?;
        for start in &recorded {
            env.reset_from(start)?;
            let target: Quat = start.goal[3..7].try_into()?;
            let orientation = env.sim().object_pose().orientation;
            // A face's outward normal in the world, and how far it leans from vertical.
            let normal = |face| rotate(&orientation, face_normal(face));
            let leaning = |v: [f64; 3]| v[2].clamp(-1.0, 1.0).acos().to_degrees();
            let lean = leaning(normal(face_toward(&orientation, UP)));
            // Pair mode: either end of the target's up axis may come up; take the higher.
            let mut axis = normal(face_toward(&target, UP));
            if axis[2] < 0.0 {
                axis = axis.map(|a| -a);
            }
            starts.push(Start {
                lean,
                tilt: leaning(axis),
                azimuth: axis[1].atan2(axis[0]).to_degrees(),
                dropped: start.failed,
            });
        }
    }
    let count = |chosen: &dyn Fn(&Start) -> bool| {
        let chosen: Vec<&Start> = starts.iter().filter(|s| chosen(s)).collect();
        let drops = chosen.iter().filter(|s| s.dropped).count();
        (chosen.len(), drops)
    };
    println!("{} starts from {}", starts.len(), paths.join(", "));
    println!(
        "by the lean of the axis to bring up (0: already up; 90: a quarter flip from lying flat):"
    );
    for (low, high) in TILT_BINS {
        let (n, drops) = count(&|s| (low..high).contains(&s.tilt));
        let rate = 100.0 * drops as f64 / n.max(1) as f64;
        println!("  {low:>2.0} to {high:>2.0} degrees: {n} starts, {drops} dropped ({rate:.1}%)");
    }
    println!("by the lean of the cube itself, whichever face it rests on:");
    for (low, high) in LEAN_BINS {
        let (n, drops) = count(&|s| (low..high).contains(&s.lean));
        println!("  {low:>2.0} to {high:>2.0} degrees: {n} starts, {drops} dropped");
    }
    println!(
        "quarter flips: dropped / starts, by lean (rows) and the axis's azimuth (columns, degrees)"
    );
    let azimuths: Vec<i32> = (-180..180).step_by(45).collect();
    let header: Vec<String> = azimuths
        .iter()
        .map(|low| format!("{:>10}", format!("{low}..{}", low + 45)))
        .collect();
    println!("  {:>9} {}", "lean", header.join(" "));
    for (low, high) in FLIP_BINS {
        let cells: Vec<String> = azimuths
            .iter()
            .map(|&azimuth| {
                let range = f64::from(azimuth)..f64::from(azimuth + 45);
                let (n, drops) =
                    count(&|s| (low..high).contains(&s.tilt) && range.contains(&s.azimuth));
                format!("{:>10}", format!("{drops}/{n}"))
            })
            .collect();
        let lean = format!("{low:.0} to {high:.0}");
        println!("  {lean:>9} {}", cells.join(" "));
    }
    Ok(())
}
