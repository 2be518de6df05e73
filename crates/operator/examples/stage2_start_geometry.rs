//! Where Stage 2's failures start from: for recorded Stage 2 starts (`dexcube eval-stage layer
//! --record-starts`, or `dexcube eval --record-layer-starts`), how many starts, and how many
//! of them the recorded policy failed from, by the cube's yaw on the palm (how far its side
//! faces turn from square to the hand's axes, 0 to 45 degrees, a cube's sides repeating every
//! 90; read from the policy's first observation, as a start route reads it, since session 59),
//! by how far it sits from the palm's resting point across the palm, and by which side
//! of that point it sits: the thumb lies towards -x and the little finger towards +x, the
//! fingertips towards -y and the wrist towards +y (before session 38 this said the fingertips
//! lay towards -x, and the sides were printed so).
//!
//! With `--mark-side SIDE OUT` (SIDE one of x-, x+, y-, y+) it also writes the starts, joined,
//! to OUT with every start on that side of the resting point marked as failed beside those
//! the recorded policy failed from, so that a recipe phase with `starts` OUT and `failed_weight` W
//! draws that side W times as often. With `--only-side SIDE OUT` it writes only the starts on
//! that side, their marks as recorded: a run that trains there alone (`start_share` 1), or
//! an evaluation of that side alone (`dexcube eval-stage layer --starts OUT`). With
//! `--max-yaw DEG` first, the side takes in only its starts whose yaw from square is at most
//! DEG degrees: the near-square placements on one side.
//!
//! `cargo run --release -p dexcube-operator --example stage2_start_geometry -- [--max-yaw DEG] [--mark-side|--only-side SIDE OUT] STARTS...`

use std::path::Path;

use dexcube_env::layer::{LayerGoals, LayerMove};
use dexcube_env::{LayerOpEnv, SimulatedEnv};
use dexcube_rl::start_route::yaw_seen;
use dexcube_sim::{Scene, SceneKind, Sim};

const YAW_BINS: [(f64, f64); 5] = [
    (0.0, 5.0),
    (5.0, 15.0),
    (15.0, 25.0),
    (25.0, 35.0),
    (35.0, 45.1),
];
/// Millimetres from the resting point, across the palm.
const OFFSET_BINS: [(f64, f64); 4] = [(0.0, 3.0), (3.0, 6.0), (6.0, 10.0), (10.0, 100.0)];

/// One start: the cube's yaw from square in degrees, its offset across the palm from the
/// resting point in millimetres (x, y), and whether the recorded policy failed from there.
struct Start {
    yaw: f64,
    offset: [f64; 2],
    failed: bool,
}

/// The four sides of the resting point, as `--mark-side` names them, with their directions
/// across the palm.
const SIDES: [(&str, &str, [f64; 2]); 4] = [
    ("x-", "x < 0 (towards the thumb)", [-1.0, 0.0]),
    ("x+", "x > 0 (towards the little finger)", [1.0, 0.0]),
    ("y-", "y < 0 (towards the fingertips)", [0.0, -1.0]),
    ("y+", "y > 0 (towards the wrist)", [0.0, 1.0]),
];

fn on_side(offset: [f64; 2], side: [f64; 2]) -> bool {
    offset[0] * side[0] + offset[1] * side[1] > 0.0
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let usage = "usage: stage2_start_geometry [--max-yaw DEG] [--mark-side|--only-side x-|x+|y-|y+ OUT] STARTS...";
    let mut paths: Vec<String> = std::env::args().skip(1).collect();
    let max_yaw = match paths.first().map(String::as_str) {
        Some("--max-yaw") => {
            let degrees = paths.get(1).ok_or(usage)?.clone();
            paths.drain(..2);
            let parsed = degrees.parse::<f64>();
            Some(parsed.map_err(|_| format!("--max-yaw takes degrees, not '{degrees}'"))?)
        }
        _ => None,
    };
    let flag = paths.first().cloned().unwrap_or_default();
    let mark = match flag.as_str() {
        "--mark-side" | "--only-side" if paths.len() > 3 => {
            let only = flag == "--only-side";
            let out = paths.remove(2);
            let name = paths.remove(1);
            paths.remove(0);
            let side = SIDES
                .iter()
                .find(|(tag, _, _)| *tag == name)
                .ok_or(format!("{flag} takes x-, x+, y- or y+, not '{name}'"))?;
            Some((side, only, out))
        }
        "--mark-side" | "--only-side" => return Err(usage.into()),
        _ => None,
    };
    if paths.is_empty() {
        return Err(usage.into());
    }
    let scene = Scene::load(SceneKind::Cube)?;
    let resting = dexcube_env::resting_point(&mut Sim::new(scene.clone()));
    let mut env = LayerOpEnv::with_scene(scene, LayerMove::UPrime, LayerGoals::Evaluation);
    let mut starts = Vec::new();
    let mut marked = Vec::new();
    let mut first_origin = None;
    for path in &paths {
        let (recorded, origin) = dexcube_rl::start_file::load_starts(Path::new(path))?;
        first_origin.get_or_insert(origin);
        for start in &recorded {
            // The yaw as the policy sees it at the first step, where a start route reads it.
            let (observation, _) = env.reset_from(start)?;
            let yaw = yaw_seen(&observation.observation);
            let pose = env.sim().object_pose();
            let offset = [0, 1].map(|k| 1000.0 * (pose.position[k] - resting[k]));
            if let Some(((_, _, side), only, _)) = &mark {
                let there = on_side(offset, *side) && max_yaw.is_none_or(|most| yaw <= most);
                let mut start = start.clone();
                if !only {
                    start.failed |= there;
                }
                if there || !only {
                    marked.push(start);
                }
            }
            starts.push(Start {
                yaw,
                offset,
                failed: start.failed,
            });
        }
    }
    let count = |chosen: &dyn Fn(&Start) -> bool| {
        let chosen: Vec<&Start> = starts.iter().filter(|s| chosen(s)).collect();
        let failed = chosen.iter().filter(|s| s.failed).count();
        let rate = 100.0 * failed as f64 / chosen.len().max(1) as f64;
        format!("{} starts, {failed} failed ({rate:.1}%)", chosen.len())
    };
    println!("{} starts from {}", starts.len(), paths.join(", "));
    println!("by the cube's yaw from square to the hand:");
    for (low, high) in YAW_BINS {
        let yawed = count(&|s| (low..high).contains(&s.yaw));
        println!("  {low:>2.0} to {high:>2.0} degrees: {yawed}");
    }
    println!("by the distance from the resting point across the palm:");
    for (low, high) in OFFSET_BINS {
        let off = count(&|s| (low..high).contains(&s.offset[0].hypot(s.offset[1])));
        println!("  {low:>2.0} to {high:>3.0} mm: {off}");
    }
    println!("by the side of the resting point (x across the palm, y along the hand):");
    for (_, name, side) in SIDES {
        let there = count(&|s| on_side(s.offset, side));
        println!("  {name}: {there}");
    }
    if let (Some(((tag, _, _), _, out)), Some(mut origin)) = (mark, first_origin) {
        origin.command = format!(
            "cargo run --release -p dexcube-operator --example stage2_start_geometry -- \
             {}{flag} {tag} {out} {} (the first's command: {})",
            max_yaw.map_or(String::new(), |most| format!("--max-yaw {most} ")),
            paths.join(" "),
            origin.command
        );
        dexcube_rl::start_file::save_starts(Path::new(&out), &marked, &origin)?;
        let failed = marked.iter().filter(|s| s.failed).count();
        println!("{out}: {} starts, {failed} marked failed", marked.len());
    }
    Ok(())
}
