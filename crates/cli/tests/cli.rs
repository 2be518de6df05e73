//! The `dexcube` binary end to end: answers on stdout, diagnostics on stderr, clean failures.

use std::io::Write;
use std::process::{Command, Output, Stdio};

fn dexcube(args: &[&str], stdin: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_dexcube"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the dexcube binary runs");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(stdin.as_bytes())
        .unwrap();
    child.wait_with_output().unwrap()
}

fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).unwrap()
}

/// A failure that names its problem on one line, with no panic or backtrace.
fn assert_clean_failure(o: &Output, code: i32, says: &str) {
    assert_eq!(o.status.code(), Some(code), "{}", stderr(o));
    assert!(stderr(o).contains(says), "stderr: {}", stderr(o));
    assert!(!stderr(o).contains("panicked"), "stderr: {}", stderr(o));
}

#[test]
fn solves_facelets_and_scrambles_optimally_with_either_method() {
    let o = dexcube(&["solve", "UFUFRRRRFDFDDBDBLLLLUBUB"], "");
    assert!(o.status.success());
    assert_eq!(stdout(&o), "R'\n");
    for method in ["table", "ida"] {
        let o = dexcube(
            &["solve", "--scramble", "R U F' D2 L B'", "--method", method],
            "",
        );
        assert!(o.status.success(), "{}", stderr(&o));
        assert_eq!(
            stdout(&o).split_whitespace().count(),
            7,
            "{method}: {}",
            stdout(&o)
        );
    }
}

#[test]
fn a_solved_cube_prints_an_empty_line() {
    let o = dexcube(&["solve", "UUUURRRRFFFFDDDDLLLLBBBB"], "");
    assert!(o.status.success());
    assert_eq!(stdout(&o), "\n");
}

#[test]
fn all_lists_every_optimal_solution() {
    let o = dexcube(&["solve", "--scramble", "R U2", "--all"], "");
    assert_eq!(stdout(&o), "U U R'\nU' U' R'\n");
}

#[test]
fn bad_input_fails_cleanly_with_a_reason() {
    let o = dexcube(&["solve", "uuuuRRRRFFFFDDDDLLLLBBBB"], "");
    assert_clean_failure(&o, 2, "lower-case 'u'");
    let o = dexcube(&["solve", "UUUURRRRFFFFDDDDLLLLBBB"], "");
    assert_clean_failure(&o, 2, "wrong length");
    let o = dexcube(&["solve", "--scramble", "R u"], "");
    assert_clean_failure(&o, 2, "lower case");
    let o = dexcube(&["solve", "--batch", "/no/such/file"], "");
    assert_clean_failure(&o, 2, "cannot open batch file /no/such/file");
    let o = dexcube(&["scramble", "--distance", "15"], "");
    assert_clean_failure(&o, 2, "largest distance is 14");
    let o = dexcube(&["eval", "--steady-radius", "0"], "");
    assert_clean_failure(&o, 2, "not a distance in metres above 0");
}

#[test]
fn batch_answers_every_line_in_order_and_reports_bad_ones() {
    let input = "UUUURRRRFFFFDDDDLLLLBBBB\nbad\nUUUUBBRRRRFFDDDDFFLLLLBB\n";
    let o = dexcube(&["solve", "--batch", "-"], input);
    assert_eq!(stdout(&o), "\nERROR\nU'\n");
    assert_clean_failure(&o, 1, "line 2: wrong length");
}

#[test]
fn scramble_is_reproducible_and_its_output_solves_at_that_distance() {
    let args = [
        "scramble",
        "--distance",
        "11",
        "--count",
        "5",
        "--seed",
        "3",
        "--show-moves",
    ];
    let first = stdout(&dexcube(&args, ""));
    assert_eq!(first, stdout(&dexcube(&args, "")));
    let cubes: String = first
        .lines()
        .map(|l| l.split('\t').next().unwrap().to_owned() + "\n")
        .collect();
    let solved = dexcube(&["solve", "--batch", "-"], &cubes);
    assert!(solved.status.success());
    for (line, answer) in first.lines().zip(stdout(&solved).lines()) {
        let scramble = line.split('\t').nth(1).unwrap();
        assert_eq!(scramble.split_whitespace().count(), 11);
        assert_eq!(answer.split_whitespace().count(), 11);
    }
}

/// An empty directory of this name under the system's temporary directory.
fn fresh_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The repository's models folder, which the demo and the evaluation use.
fn models() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

/// A copy of the shipped policy `name` (weights and card) as `dir/as_name`, for a test that
/// writes to its card; returns the copy's prefix.
fn copy_policy(name: &str, dir: &std::path::Path, as_name: &str) -> std::path::PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    for ext in ["json", "safetensors"] {
        std::fs::copy(
            models().join(name).with_extension(ext),
            dir.join(as_name).with_extension(ext),
        )
        .unwrap();
    }
    dir.join(as_name)
}

/// The flags that point a command at the shipped policies.
fn shipped_policy_flags() -> [String; 4] {
    let path = |name: &str| models().join(name).to_str().unwrap().to_string();
    [
        "--rot-policy".into(),
        path("rot"),
        "--layer-policy".into(),
        path("layer"),
    ]
}

/// `eval` of one cube at move `distance`, with rollback only, on one thread, into `out`; the
/// policies and any other flags follow.
fn eval_one_cube<'a>(distance: &'a str, out: &'a str) -> [&'a str; 10] {
    [
        "eval",
        "--per-distance",
        "1",
        "--distances",
        distance,
        "--rollback-only",
        "--threads",
        "1",
        "--out",
        out,
    ]
}

#[test]
fn demo_narrates_the_hand_solving_with_the_shipped_policies() {
    let policies = shipped_policy_flags();
    let demo = ["demo", "--distance", "1", "--seed", "3"];
    let o = dexcube(
        &[&demo[..], &policies.each_ref().map(String::as_str)].concat(),
        "",
    );
    let out = stdout(&o);
    assert!(out.contains("Plan, 1 quarter turns (optimal: 1)"), "{out}");
    // Stage 1 either brings the face up or, when it already is, says it is not needed.
    assert!(
        out.contains("Stage 1: ") && out.contains("Stage 2: U' on the top layer"),
        "{out}"
    );
    let last = out.lines().rev().nth(1).unwrap_or("");
    assert!(
        last.starts_with("Solved with") || last.starts_with("Failed ("),
        "{out}"
    );
    assert_eq!(
        o.status.success(),
        last.starts_with("Solved"),
        "exit status follows the outcome"
    );
}

#[test]
fn demo_without_policies_says_where_to_get_them() {
    let o = dexcube(&["demo", "--rot-policy", "/no/such/rot"], "");
    assert_clean_failure(&o, 2, "no policy at /no/such/rot.json");
}

#[test]
fn eval_writes_its_table_and_a_rerun_continues_it() {
    // A dot in the table's name stays in its files' names.
    let out = std::env::temp_dir().join("dexcube-cli-eval/table-0.5");
    let file = |extension: &str| out.with_file_name(format!("table-0.5.{extension}"));
    let _ = std::fs::remove_dir_all(out.parent().unwrap());
    let policies = shipped_policy_flags();
    let args = [
        &eval_one_cube("1", out.to_str().unwrap())[..],
        &["--seed", "5"],
        &policies.each_ref().map(String::as_str),
    ]
    .concat();
    let o = dexcube(&args, "");
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = std::fs::read_to_string(file("csv")).unwrap();
    assert_eq!(csv.lines().count(), 2, "{csv}");
    let md = std::fs::read_to_string(file("md")).unwrap();
    assert!(md.contains("| 1 | 1 |") && md.contains("--seed 5 --rollback-only --rot-policy"));
    let again = dexcube(&args, "");
    assert!(
        stderr(&again).contains("0 cubes to go (1 already in"),
        "{}",
        stderr(&again)
    );
    // Continuing it with another seed would mix two runs in one table: refused.
    let other_seed: Vec<&str> = args
        .iter()
        .map(|&a| if a == "5" { "6" } else { a })
        .collect();
    let refused = dexcube(&other_seed, "");
    assert_clean_failure(&refused, 2, "holds results of other policies, another seed");
    // So would continuing it with the paper's operator, or driving the stages otherwise.
    for other in [
        &["--paper-operator"][..],
        &["--stage1-held", "0"],
        &["--opening", "at-once"],
        &["--plan-from-face-up"],
        &["--stage1-price", "5"],
        &["--already-up", "top"],
        &["--steady-radius", "0.03"],
    ] {
        let refused = dexcube(&[&args[..], other].concat(), "");
        assert_clean_failure(&refused, 2, "or another operator");
    }
    // So would continuing it with the same weights acting otherwise: Stage 1 led on.
    let led = out.with_file_name("rot-led");
    let rot = models().join("rot");
    let lead = [
        &["goal-lead", rot.to_str().unwrap(), "--share", "0.5"][..],
        &["--out", led.to_str().unwrap()],
    ]
    .concat();
    assert!(dexcube(&lead, "").status.success());
    let with_led: Vec<&str> = args
        .iter()
        .map(|&a| {
            if a == rot.to_str().unwrap() {
                led.to_str().unwrap()
            } else {
                a
            }
        })
        .collect();
    assert_ne!(with_led, args);
    let refused = dexcube(&with_led, "");
    assert_clean_failure(&refused, 2, "holds results of other policies");
    // Naming the defaults is the same operator.
    let defaults = [&args[..], &["--stage1-held", "5", "--opening", "gradual"]].concat();
    assert!(dexcube(&defaults, "").status.success());
    // Continued with the open-loop variant, the table holds both, as one run without either
    // variant flag makes them, and its markdown names that command.
    let open_loop: Vec<&str> = args
        .iter()
        .map(|&a| {
            if a == "--rollback-only" {
                "--no-rollback"
            } else {
                a
            }
        })
        .collect();
    assert!(dexcube(&open_loop, "").status.success());
    let md = std::fs::read_to_string(file("md")).unwrap();
    assert!(md.contains("--seed 5 --rot-policy"), "{md}");
}

/// `eval-stage --after-gesture --record-starts` with the gesturing policy `gesturing` (made
/// from `layer`) keeps, for an episode that makes the gesture, the state after it with the
/// angle the layer turned meanwhile, and for one that does not, its fresh placement as
/// `--record-starts` alone keeps it, marked failed alike; it refuses a policy with no
/// gesture, and `--record-starts` with `--starts` is refused without it.
fn after_gesture_starts_are_where_the_policy_first_acts(
    dir: &std::path::Path,
    [rot, layer, gesturing]: [&str; 3],
) {
    let files = ["fresh", "after"].map(|name| dir.join(format!("{name}.safetensors")));
    let [fresh, after] = files.each_ref().map(|file| file.to_str().unwrap());
    let record = |policy: &str, flags: &[&str]| {
        let args = ["eval-stage", "layer", "--episodes", "8", "--threads", "2"];
        let policies = [
            "--seed",
            "13000000",
            "--rot-policy",
            rot,
            "--layer-policy",
            policy,
        ];
        dexcube(&[&args[..], &policies, flags].concat(), "")
    };
    let o = record(gesturing, &["--record-starts", fresh]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = record(gesturing, &["--after-gesture", "--record-starts", after]);
    assert!(o.status.success(), "{}", stderr(&o));
    let printed = stdout(&o);
    let load = |file: &std::path::Path| dexcube_rl::start_file::load_starts(file).unwrap();
    let ((fresh_starts, _), (after_starts, origin)) = (load(&files[0]), load(&files[1]));
    assert!(origin.command.contains("--after-gesture --record-starts"));
    let moved: Vec<usize> = (0..8)
        .filter(|&k| fresh_starts[k].state != after_starts[k].state)
        .collect();
    assert!(
        printed.contains(&format!(
            "began with the start gesture in {} episodes",
            moved.len()
        )) && (1..8).contains(&moved.len()),
        "{printed}"
    );
    for (k, (fresh, after)) in fresh_starts.iter().zip(&after_starts).enumerate() {
        assert_eq!(fresh.goal[1], 0.0, "a fresh placement has turned nothing");
        assert_eq!(fresh.failed, after.failed, "episode {k}");
        if moved.contains(&k) {
            assert_ne!(
                after.goal[1], 0.0,
                "the layer moves while the gesture is made"
            );
        } else {
            assert_eq!(fresh, after, "episode {k}");
        }
    }
    let o = record(layer, &["--after-gesture", "--record-starts", after]);
    assert_clean_failure(
        &o,
        2,
        "makes none: make one that does with `dexcube start-gesture`",
    );
    let o = record(gesturing, &["--starts", fresh, "--record-starts", after]);
    assert_clean_failure(&o, 2, "would write the starts it replays again");
}

/// `eval-stage --record-starts` keeps where each fresh episode began, marked failed as the
/// stage's starts are; running the same policy from that file replays every episode: the
/// same successes, and a failure from exactly the starts marked failed.
#[test]
fn eval_stage_records_fresh_starts_that_replay_its_episodes() {
    let dir = std::env::temp_dir().join("dexcube-cli-fresh-starts");
    let _ = std::fs::remove_dir_all(&dir);
    let flags = shipped_policy_flags();
    let policies = flags.each_ref().map(String::as_str);
    for stage in ["rot", "layer"] {
        let file = dir.join(format!("{stage}.safetensors"));
        let run = |source: &[&str]| {
            let o = dexcube(
                &[
                    &["eval-stage", stage, "--episodes", "6", "--threads", "2"][..],
                    &policies,
                    source,
                ]
                .concat(),
                "",
            );
            assert!(o.status.success(), "{}", stderr(&o));
            stdout(&o)
        };
        let fresh = run(&[
            "--seed",
            "1000000",
            "--record-starts",
            file.to_str().unwrap(),
        ]);
        // The number written just before `marker`.
        let number_before = |text: &str, marker: &str| -> usize {
            let head = &text[..text.find(marker).unwrap_or_else(|| panic!("{text}"))];
            let digits = head.len() - head.trim_end_matches(|c: char| c.is_ascii_digit()).len();
            head[head.len() - digits..].parse().unwrap()
        };
        let wins = number_before(&fresh, "/6 = ");
        let failed = number_before(&fresh, " of which this policy");
        let replayed = run(&["--starts", file.to_str().unwrap()]);
        assert_eq!(
            number_before(&replayed, "/6 = "),
            wins,
            "{fresh}\n{replayed}"
        );
        assert!(
            replayed.contains(&format!(
                ": {failed}; this one failed so from {failed} of them"
            )),
            "{fresh}\n{replayed}"
        );
    }
}

/// `eval --record-starts` keeps where each Stage 1 run began, `--record-layer-starts` where
/// each Stage 2 run began, and `eval-stage rot|layer --starts` runs the policy from them; a
/// file that holds no starts, or another stage's, is refused.
#[test]
fn eval_records_stage_starts_that_eval_stage_runs_from() {
    let dir = std::env::temp_dir().join("dexcube-cli-starts");
    let _ = std::fs::remove_dir_all(&dir);
    let starts = dir.join("starts.safetensors");
    let layer_starts = dir.join("layer-starts.safetensors");
    let flags = shipped_policy_flags();
    let policies = flags.each_ref().map(String::as_str);
    let o = dexcube(
        &[
            &eval_one_cube("4", dir.join("table").to_str().unwrap())[..],
            &[
                "--record-starts",
                starts.to_str().unwrap(),
                "--record-layer-starts",
                layer_starts.to_str().unwrap(),
            ][..],
            &policies,
        ]
        .concat(),
        "",
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = std::fs::read_to_string(dir.join("table.csv")).unwrap();
    let row: Vec<&str> = csv.lines().nth(1).unwrap().split(',').collect();
    // Every Stage 1 run that kept the cube began somewhere, and so did one that dropped it
    // after the hand had opened (20 steps).
    let dropped_later = row[8]
        .strip_prefix("Dropped in Stage 1 at step ")
        .is_some_and(|step| step.parse::<usize>().unwrap() > 20);
    let runs = row[9].parse::<usize>().unwrap() + usize::from(dropped_later);
    assert!(runs > 0, "{csv}");
    assert!(
        stderr(&o).contains(&format!("recorded {runs} Stage 1 starts")),
        "{}",
        stderr(&o)
    );
    // A solved cube's Stage 2 runs all kept it past the opening.
    assert_eq!(row[3], "true", "{csv}");
    let turns = row[11].parse::<usize>().unwrap();
    assert!(
        stderr(&o).contains(&format!("recorded {turns} Stage 2 starts")),
        "{}",
        stderr(&o)
    );
    let from = |file: &std::path::Path, stage: &str| {
        dexcube(
            &[
                &[
                    "eval-stage",
                    stage,
                    "--episodes",
                    "1000",
                    "--threads",
                    "1",
                    "--starts",
                    file.to_str().unwrap(),
                ][..],
                &policies,
            ]
            .concat(),
            "",
        )
    };
    let o = from(&starts, "rot");
    assert!(o.status.success(), "{}", stderr(&o));
    let said = stdout(&o);
    assert!(
        said.contains(&format!("/{runs} = ")) && said.contains("from the recorded starts in"),
        "{said}"
    );
    assert!(
        said.contains("starts from which the recorded policy dropped the cube or missed the pose")
    );
    let o = from(&layer_starts, "layer");
    assert!(o.status.success(), "{}", stderr(&o));
    let said = stdout(&o);
    assert!(said.contains(&format!("/{turns} = ")), "{said}");
    assert!(said.contains("did not leave the layer turned with the cube square"));
    assert_clean_failure(&from(&starts, "layer"), 2, "holds rot starts, not layer's");
    assert_clean_failure(
        &from(&layer_starts, "rot"),
        2,
        "holds layer starts, not rot's",
    );
    let policy = models().join("rot.safetensors");
    assert_clean_failure(&from(&policy, "rot"), 2, "not a file of recorded starts");
}

#[test]
fn render_writes_a_picture_and_missing_assets_fail_cleanly() {
    let out = std::env::temp_dir().join("dexcube-cli-render.png");
    let o = dexcube(
        &[
            "render",
            "--scene",
            "cube",
            "--scramble",
            "R U",
            "--width",
            "160",
            "--height",
            "120",
            "--out",
            out.to_str().unwrap(),
        ],
        "",
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let png = std::fs::read(&out).unwrap();
    assert_eq!(&png[1..4], b"PNG");

    let o = Command::new(env!("CARGO_BIN_EXE_dexcube"))
        .args(["render", "--out", "/tmp/never.png"])
        .env("DEXCUBE_ASSETS", "/no/such/assets")
        .output()
        .unwrap();
    assert_clean_failure(&o, 2, "missing model file /no/such/assets/cube/scene.xml");
    assert!(stderr(&o).contains("scripts/setup"));
}

#[test]
fn each_environment_takes_only_objects_it_can_hold() {
    let layer = dexcube(&["env", "info", "layer"], "");
    assert!(
        layer.status.success() && stdout(&layer).contains("LayerOpEnv (U', cube)"),
        "LayerOpEnv turns the physical cube by default: {}",
        stdout(&layer)
    );
    let rot = dexcube(&["env", "info", "rot", "--object", "cube"], "");
    assert!(
        rot.status.success() && stdout(&rot).contains("CubeRotEnv (paper mode, cube)"),
        "{}",
        stdout(&rot)
    );
    assert_clean_failure(
        &dexcube(&["env", "info", "rot", "--object", "block"], ""),
        2,
        "CubeRotEnv holds the rigid or the physical cube",
    );
    assert_clean_failure(
        &dexcube(&["env", "info", "layer", "--object", "rigid"], ""),
        2,
        "LayerOpEnv needs a layer to turn",
    );
    // Leaving the cube square is a test only the physical cube can fail, in either stage.
    for (env, goal) in [(&["layer"][..], 2), (&["rot", "--object", "cube"], 8)] {
        let square = dexcube(&[&["env", "info"][..], env, &["--square"]].concat(), "");
        assert!(
            square.status.success()
                && stdout(&square).contains(&format!("goal:        {goal} floats")),
            "{}",
            stdout(&square)
        );
    }
    for other in [&["layer", "--object", "block"][..], &["rot"]] {
        let args = [&["env", "info"][..], other, &["--square"]].concat();
        assert_clean_failure(&dexcube(&args, ""), 2, "square is for the physical cube");
    }
    // A tighter training threshold is the success test's, and names the environment.
    for (env, test) in [
        ("rot", "orientation within 0.05 rad"),
        ("layer", "angle within 0.05 rad"),
    ] {
        let tight = dexcube(&["env", "info", env, "--angle-threshold", "0.05"], "");
        assert!(
            tight.status.success()
                && stdout(&tight).contains(test)
                && stdout(&tight).contains("trained to 0.05 rad)"),
            "{}",
            stdout(&tight)
        );
    }
}

/// A recipe of `phases` (JSON objects of a phase's `name`, `env` and more) on small networks
/// and short epochs, one environment, for runs of seconds.
fn tiny_recipe(phases: &[serde_json::Value]) -> serde_json::Value {
    let phases: Vec<serde_json::Value> = phases
        .iter()
        .map(|phase| {
            let mut full = serde_json::json!({
                "max_epochs": 1, "until": null, "noise_eps": null, "random_eps": null,
                "anchor": 0.0, "critic_only_epochs": 0,
            });
            for (key, value) in phase.as_object().unwrap() {
                full[key] = value.clone();
            }
            full
        })
        .collect();
    serde_json::json!({
        "name": "tiny",
        "config": {
            "hidden": [32, 32], "cycles_per_epoch": 2, "batches_per_cycle": 2,
            "test_episodes": 1, "twin_critics": true, "target_noise": 0.2, "policy_delay": 2,
        },
        "envs": 1,
        "phases": phases,
    })
}

/// Writes `recipe` as `dir/name.json` and gives its path.
fn recipe_file(dir: &std::path::Path, name: &str, recipe: &serde_json::Value) -> String {
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join(format!("{name}.json"));
    std::fs::write(&path, serde_json::to_string_pretty(recipe).unwrap()).unwrap();
    path.to_str().unwrap().to_string()
}

/// Recipes a training run cannot use are refused before it starts, each with its reason, the
/// phase named; so are a folder that holds a run already and a folder that holds none.
#[test]
fn train_refuses_recipes_it_cannot_run() {
    let dir = std::env::temp_dir().join("dexcube-cli-bad-recipes");
    let _ = std::fs::remove_dir_all(&dir);
    let phase = |env: serde_json::Value| serde_json::json!({"name": "p", "env": env});
    for (skill, env, says) in [
        (
            "rot",
            serde_json::json!({"quarter_goals": true}),
            "move and quarter_goals are LayerOpEnv's",
        ),
        (
            "rot",
            serde_json::json!({"square": true}),
            "square is for the physical cube",
        ),
        (
            "layer",
            serde_json::json!({"object": "block", "see_misalignment": true}),
            "see_misalignment is for the physical cube",
        ),
        (
            "rot",
            serde_json::json!({"see_grip": true}),
            "see_grip is for the physical cube",
        ),
        (
            "rot",
            serde_json::json!({"intact": true}),
            "intact is for the physical cube",
        ),
        (
            "layer",
            serde_json::json!({"intact": true}),
            "intact is for CubeRotEnv",
        ),
        (
            "layer",
            serde_json::json!({"mode": "pair"}),
            "mode is CubeRotEnv's success test",
        ),
        (
            "rot",
            serde_json::json!({"object": "block"}),
            "CubeRotEnv holds the rigid or the physical cube",
        ),
        (
            "rot",
            serde_json::json!({"object": "glass"}),
            "unknown object 'glass'",
        ),
        (
            "rot",
            serde_json::json!({"control_substeps": 3}),
            "3 substeps per control step: use a number that divides",
        ),
        (
            "rot",
            serde_json::json!({"physics_spread": -0.1}),
            "physics_spread must be 0 or more",
        ),
        (
            "layer",
            serde_json::json!({"angle_threshold": 4.0}),
            "angle_threshold must be an angle in radians above 0",
        ),
        (
            "rot",
            serde_json::json!({"start_share": 0.2}),
            "name them in starts",
        ),
        (
            "rot",
            serde_json::json!({"object": "cube", "starts": "s", "start_share": 2.0}),
            "start_share must be between 0 and 1",
        ),
        (
            "rot",
            serde_json::json!({"object": "cube", "starts": "s", "failed_weight": 0.0}),
            "failed_weight must be a positive number",
        ),
        (
            "layer",
            serde_json::json!({"move": "U", "starts": "s"}),
            "train them with the move U'",
        ),
        (
            "rot",
            serde_json::json!({"object": "cube", "starts": "/no/such/starts"}),
            "record starts with `dexcube eval",
        ),
        (
            "rot",
            serde_json::json!({"colour": "red"}),
            "unknown field `colour`",
        ),
    ] {
        let recipe = recipe_file(&dir, "bad", &tiny_recipe(&[phase(env)]));
        let out = dir.join("run");
        let o = dexcube(
            &[
                "train",
                skill,
                "--recipe",
                &recipe,
                "--out",
                out.to_str().unwrap(),
            ],
            "",
        );
        assert_clean_failure(&o, 2, says);
        if !says.starts_with("unknown field") {
            assert_clean_failure(&o, 2, "phase 'p'");
        }
        let _ = std::fs::remove_dir_all(&out);
    }
    let mut anchored = tiny_recipe(&[phase(serde_json::json!({}))]);
    anchored["phases"][0]["anchor"] = 10.0.into();
    for (recipe, says) in [
        (anchored, "starts from random weights"),
        (serde_json::json!({"name": "x"}), "is not a recipe"),
    ] {
        let recipe = recipe_file(&dir, "bad", &recipe);
        let o = dexcube(
            &[
                "train",
                "rot",
                "--recipe",
                &recipe,
                "--out",
                "/nonexistent/run",
            ],
            "",
        );
        assert_clean_failure(&o, 2, says);
    }
    let o = dexcube(&["train", "rot", "--recipe", "nope"], "");
    assert_clean_failure(
        &o,
        2,
        "no recipe 'nope': name a shipped one (dexcube, paper)",
    );
    let o = dexcube(&["train", "--resume", dir.to_str().unwrap()], "");
    assert_clean_failure(&o, 2, "holds no recipe's run");
    let o = dexcube(&["train", "--resume", "/tmp", "--seed", "3"], "");
    assert_eq!(
        o.status.code(),
        Some(2),
        "a resume takes the run's own seed"
    );
    let o = dexcube(&["train"], "");
    assert_clean_failure(&o, 2, "<SKILL>");
    // A folder that holds a run is resumed, not trained into again.
    let recipe = recipe_file(&dir, "one", &tiny_recipe(&[phase(serde_json::json!({}))]));
    let out = dir.join("done");
    let train = [
        "train",
        "rot",
        "--recipe",
        &recipe,
        "--out",
        out.to_str().unwrap(),
    ];
    assert!(dexcube(&train, "").status.success());
    assert_clean_failure(
        &dexcube(&train, ""),
        2,
        "holds a run already: go on with `dexcube train --resume",
    );
    // Shipping a residual: an actor not trained as one is refused.
    let [base, actor] = ["rot", "rot-td3-19"].map(|name| models().join(name));
    let [base, actor] = [&base, &actor].map(|path| path.to_str().unwrap());
    let o = dexcube(&["residual", base, actor, "--out", "/nonexistent/r"], "");
    assert_clean_failure(&o, 2, "it was not trained as a residual");
}

/// A policy of either stage trained onto a view beyond the paper's, from a phase that had the
/// paper's, gains its inputs (Stage 2 the cube's misalignment: 63 observations, from 62;
/// Stage 1 that and the grip: 68, from 61), and `eval-stage` and the operator give it that
/// view, told by its size; `eval-stage` on the other object (the rigid cube, the block), which
/// the views are not for, refuses it cleanly.
#[test]
fn a_policy_trained_seeing_more_is_evaluated_with_it() {
    for (stage, first, seen_env, observation, seen, other_object) in [
        (
            "rot",
            serde_json::json!({"mode": "pair"}),
            serde_json::json!({
                "mode": "pair", "object": "cube", "square": true,
                "see_misalignment": true, "see_grip": true,
            }),
            68,
            "misalignment and grip",
            "rigid",
        ),
        (
            "layer",
            serde_json::json!({"object": "block", "quarter_goals": true}),
            serde_json::json!({
                "object": "cube", "square": true, "quarter_goals": true,
                "see_misalignment": true,
            }),
            63,
            "misalignment",
            "block",
        ),
    ] {
        let dir = std::env::temp_dir().join(format!("dexcube-cli-see-more-{stage}"));
        let _ = std::fs::remove_dir_all(&dir);
        let phases = [
            serde_json::json!({"name": "paper-view", "env": first}),
            serde_json::json!({"name": "seen", "env": seen_env, "critic_only_epochs": 1}),
        ];
        let recipe = recipe_file(&dir, "recipe", &tiny_recipe(&phases));
        let run = dir.join("run");
        let out = run.to_str().unwrap();
        let o = dexcube(
            &[
                "train",
                stage,
                "--recipe",
                &recipe,
                "--threads",
                "1",
                "--out",
                out,
            ],
            "",
        );
        assert!(o.status.success(), "{}", stderr(&o));
        let card: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(run.join("policy.json")).unwrap())
                .unwrap();
        assert_eq!(card["dims"]["observation"], observation);
        assert_eq!(
            card["metadata"]["environment"]["observation"],
            format!("with the {seen}")
        );
        let policy = run.join("policy");
        let policy = policy.to_str().unwrap().to_string();
        let [rot_flag, rot, layer_flag, layer] = shipped_policy_flags();
        let (rot, layer) = match stage {
            "rot" => (policy.clone(), layer),
            _ => (rot, policy.clone()),
        };
        let policies = [&rot_flag[..], &rot, &layer_flag, &layer];
        let eval_stage_on = |object: &str| {
            let args = ["eval-stage", stage, "--object", object, "--episodes", "2"];
            dexcube(&[&args[..], &["--threads", "1"], &policies].concat(), "")
        };
        let o = eval_stage_on("cube");
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(
            stdout(&o).contains(if stage == "rot" { "Stage 1" } else { "Stage 2" }),
            "{}",
            stdout(&o)
        );
        let o = eval_stage_on(other_object);
        assert_clean_failure(&o, 2, &format!("trained seeing the {seen}, a view of"));
        let table = dir.join("table");
        let o = dexcube(
            &[&eval_one_cube("1", table.to_str().unwrap())[..], &policies].concat(),
            "",
        );
        assert!(o.status.success(), "{}", stderr(&o));
    }
}

/// The shipped recipes print as recipe files that run as they are.
#[test]
fn a_shipped_recipe_prints_as_a_file_that_runs() {
    for skill in ["rot", "layer"] {
        for name in ["dexcube", "paper"] {
            let o = dexcube(&["train", skill, "--recipe", name, "--print-recipe"], "");
            assert!(o.status.success(), "{}", stderr(&o));
            let recipe: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
            assert_eq!(recipe["name"], name);
            let phases = recipe["phases"].as_array().unwrap();
            assert!(!phases.is_empty());
            if name == "paper" {
                assert_eq!(recipe["config"]["twin_critics"], false, "the paper's DDPG");
                assert_eq!(phases.len(), 1);
            }
        }
    }
}

/// A recipe killed at moments spread over its run (SIGKILL, so nothing is tidied) and resumed
/// each time with `--resume DIR` alone writes the rows of an uninterrupted run, clock times
/// aside, and the same policy, bit for bit.
#[test]
fn a_recipe_killed_at_any_moment_resumes_to_the_uninterrupted_run() {
    let dir = std::env::temp_dir().join("dexcube-cli-kill");
    let _ = std::fs::remove_dir_all(&dir);
    let phases = [
        serde_json::json!({"name": "axis-rigid", "env": {"mode": "axis"}, "max_epochs": 3}),
        serde_json::json!({
            "name": "pair-cube", "env": {"mode": "pair", "object": "cube", "square": true},
            "max_epochs": 3, "anchor": 10.0, "critic_only_epochs": 1, "noise_eps": 0.1,
        }),
    ];
    let recipe = recipe_file(&dir, "recipe", &tiny_recipe(&phases));
    let train = |out: &std::path::Path| {
        Command::new(env!("CARGO_BIN_EXE_dexcube"))
            .args([
                "train",
                "rot",
                "--recipe",
                &recipe,
                "--seed",
                "5",
                "--threads",
                "1",
            ])
            .args(["--out", out.to_str().unwrap()])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap()
    };
    let untimed = |out: &std::path::Path| -> Vec<String> {
        std::fs::read_to_string(out.join("metrics.csv"))
            .unwrap()
            .lines()
            .map(|line| {
                let cells: Vec<&str> = line.split(',').collect();
                [&cells[..6], &cells[7..12]].concat().join(",")
            })
            .collect()
    };
    let whole = dir.join("whole");
    let started = std::time::Instant::now();
    assert!(train(&whole).wait().unwrap().success());
    let took = started.elapsed();
    let expected = untimed(&whole);
    assert_eq!(expected.len(), 7, "a header and six epochs");
    let split = dir.join("split");
    let mut child = train(&split);
    let mut kills = 0;
    for share in [0.2, 0.45, 0.7] {
        std::thread::sleep(took.mul_f64(share));
        if child.try_wait().unwrap().is_some() {
            break;
        }
        child.kill().unwrap();
        child.wait().unwrap();
        kills += 1;
        child = Command::new(env!("CARGO_BIN_EXE_dexcube"))
            .args([
                "train",
                "--resume",
                split.to_str().unwrap(),
                "--threads",
                "1",
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
    }
    assert!(child.wait().unwrap().success());
    assert!(kills >= 1, "at least one kill landed before the run ended");
    assert_eq!(untimed(&split), expected, "after {kills} kills");
    assert_eq!(
        std::fs::read(split.join("policy.safetensors")).unwrap(),
        std::fs::read(whole.join("policy.safetensors")).unwrap()
    );
}

/// `eval-stage --record` writes the figure on the policy's own object as its evaluation, and
/// one on another object beside it; an object the stage cannot hold is refused.
#[test]
fn eval_stage_records_each_object_under_its_own_name() {
    let dir = std::env::temp_dir().join("dexcube-cli-eval-stage");
    // A Stage 2 with the paper's view, which both objects can show (the shipped one also
    // sees the cube's misalignment, which only the physical cube has).
    let layer = copy_policy("layer-anchor69", &dir, "layer");
    let layer = layer.to_str().unwrap();
    let rot = models().join("rot");
    let rot = rot.to_str().unwrap();
    let run = |object: &str| {
        let o = dexcube(
            &[
                "eval-stage",
                "layer",
                "--episodes",
                "2",
                "--seed",
                "7",
                "--threads",
                "1",
                "--layer-policy",
                layer,
                "--rot-policy",
                rot,
                "--object",
                object,
                "--record",
            ],
            "",
        );
        assert!(o.status.success(), "{}", stderr(&o));
        stdout(&o)
    };
    assert!(run("block").contains("on the block"));
    assert!(run("cube").contains("on the cube"));
    let card: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("layer.json")).unwrap()).unwrap();
    let metadata = &card["metadata"];
    // It was trained on the physical cube: the block is the other object.
    assert_eq!(metadata["environment"]["object"], "cube");
    assert_eq!(metadata["evaluation"]["episodes"], 2);
    let command = metadata["evaluation"]["command"].as_str().unwrap();
    assert!(
        command.contains("--object cube") && command.ends_with(&format!("--layer-policy {layer}")),
        "{command}"
    );
    assert!(
        metadata["evaluation_on_block"]["command"]
            .as_str()
            .unwrap()
            .contains("--object block")
    );
    assert_clean_failure(
        &dexcube(
            &[
                "eval-stage",
                "rot",
                "--episodes",
                "2",
                "--object",
                "block",
                "--rot-policy",
                rot,
                "--layer-policy",
                layer,
            ],
            "",
        ),
        2,
        "CubeRotEnv holds the rigid or the physical cube",
    );
}

/// `plot` draws committed runs as one curve per environment (and learner) with a CSV of the
/// figures, and refuses a seed given twice or several runs without a figure to draw them into.
#[test]
fn plot_draws_runs_across_seeds_and_refuses_a_seed_twice() {
    let training = concat!(env!("CARGO_MANIFEST_DIR"), "/../../results/training/");
    let run = |name: &str| format!("{training}{name}");
    let (rot, rot_again, layer) = (
        run("rot-pair-cube-square-anchor10-seed0"),
        run("rot-pair-cube-square-anchor5-seed0"),
        run("layer-Up-quarter-cube-square-anchor10-seed0"),
    );
    let out = std::env::temp_dir().join("dexcube-cli-plot/seeds.png");
    let _ = std::fs::remove_dir_all(out.parent().unwrap());
    std::fs::create_dir_all(out.parent().unwrap()).unwrap();
    let o = dexcube(&["plot", &rot, &layer, "--out", out.to_str().unwrap()], "");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::metadata(&out).unwrap().len() > 1000);
    let csv = std::fs::read_to_string(out.with_extension("csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    let first = |label: &str| {
        rows.iter()
            .find(|r| r.starts_with(&format!("\"{label}")))
            // The label is quoted (it holds commas); the fields after it are plain.
            .map(|r| {
                r[r.find("\",").unwrap() + 2..]
                    .split(',')
                    .map(str::to_string)
                    .collect::<Vec<_>>()
            })
            .unwrap_or_else(|| panic!("no row for {label} in {csv}"))
    };
    // One seed each: the mean is that run's test success and the deviation 0. Fields:
    // seeds, episodes, mean, deviation.
    let rot_row = first("CubeRotEnv");
    let layer_row = first("LayerOpEnv");
    for row in [&rot_row, &layer_row] {
        assert_eq!(row[0], "0");
        assert_eq!(row[3], "0.0000");
    }
    let metrics = std::fs::read_to_string(format!("{rot}/metrics.csv")).unwrap();
    let epoch0: Vec<&str> = metrics.lines().nth(1).unwrap().split(',').collect();
    assert_eq!(rot_row[1], epoch0[1], "episodes of the first epoch");
    let success: f64 = epoch0[4].parse().unwrap();
    assert_eq!(rot_row[2], format!("{success:.4}"));

    let o = dexcube(
        &["plot", &rot, &rot_again, "--out", out.to_str().unwrap()],
        "",
    );
    assert_clean_failure(&o, 2, "are both seed 0 of CubeRotEnv");
    // The same run under another seed is a second seed; with its anchor changed, it is not a
    // seed of one experiment.
    let other = out.parent().unwrap().join("other-seed");
    std::fs::create_dir_all(other.join("checkpoint")).unwrap();
    let state = std::fs::read_to_string(format!("{rot}/checkpoint/state.json")).unwrap();
    let mut state: serde_json::Value = serde_json::from_str(&state).unwrap();
    state["seed"] = 1.into();
    let plot_beside_rot = |state: &serde_json::Value| {
        std::fs::write(other.join("checkpoint/state.json"), state.to_string()).unwrap();
        let other = other.to_str().unwrap();
        dexcube(&["plot", &rot, other, "--out", out.to_str().unwrap()], "")
    };
    let o = plot_beside_rot(&state);
    assert!(o.status.success(), "{}", stderr(&o));
    let anchor = state["config"]["anchor"].clone();
    state["config"]["anchor"] = 5.0.into();
    let o = plot_beside_rot(&state);
    assert_clean_failure(&o, 2, "with different hyperparameters");
    // With TD3's critics it is another learner's run: its own curve beside DDPG's.
    state["config"]["anchor"] = anchor;
    state["config"]["twin_critics"] = true.into();
    let o = plot_beside_rot(&state);
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = std::fs::read_to_string(out.with_extension("csv")).unwrap();
    assert!(
        csv.lines().any(|r| r.contains("(TD3)\""))
            && csv
                .lines()
                .any(|r| !r.contains("TD3") && r.contains("CubeRotEnv")),
        "{csv}"
    );
    let o = dexcube(&["plot", &rot, &layer], "");
    assert_clean_failure(&o, 2, "pass --out PNG");
    let o = dexcube(
        &["plot", "/nonexistent/run", "--out", out.to_str().unwrap()],
        "",
    );
    assert_clean_failure(&o, 2, "is not a training run's folder");
}

/// `average` (of weights) and `ensemble` (of actions) each write a policy that eval-stage
/// runs, and refuse members that do not fit, naming them.
#[test]
fn average_and_ensemble_write_a_policy_eval_stage_runs_and_refuse_members_that_do_not_fit() {
    let dir = std::env::temp_dir().join("dexcube-cli-combine");
    let _ = std::fs::remove_dir_all(&dir);
    let [rot, layer, layer_blind] =
        ["rot-dropw20", "layer", "layer-td3-27"].map(|name| models().join(name));
    let [rot, layer, layer_blind] = [&rot, &layer, &layer_blind].map(|p| p.to_str().unwrap());
    let cases = [
        // A single Stage 1 (the default before the ensemble) with itself; a Stage 2 among the
        // members.
        (
            "average",
            "rot",
            [rot, rot],
            [rot, layer],
            "layer.safetensors does not fit",
        ),
        // The seen Stage 2 with a blind one, which reads the leading 62 of its 63 numbers; the
        // blind one first cannot give the seen one its misalignment.
        (
            "ensemble",
            "layer",
            [layer, layer_blind],
            [layer_blind, layer],
            "the first observes the most",
        ),
    ];
    for (command, stage, members, misfit, refusal) in cases {
        let out = dir.join(format!("{command}-{stage}"));
        let out = out.to_str().unwrap();
        let o = dexcube(&[command, members[0], members[1], "--out", out], "");
        assert!(o.status.success(), "{}", stderr(&o));
        let card: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(format!("{out}.json")).unwrap()).unwrap();
        assert_eq!(card["metadata"]["environment"]["env"], stage, "{command}");
        assert!(
            card["metadata"]["command"]
                .as_str()
                .unwrap()
                .starts_with(&format!("dexcube {command} "))
        );
        let (rot_policy, layer_policy) = if stage == "rot" {
            (out, layer)
        } else {
            (rot, out)
        };
        let o = dexcube(
            &[
                "eval-stage",
                stage,
                "--episodes",
                "2",
                "--threads",
                "1",
                "--rot-policy",
                rot_policy,
                "--layer-policy",
                layer_policy,
            ],
            "",
        );
        assert!(o.status.success(), "{command}: {}", stderr(&o));
        assert!(stdout(&o).contains("/2 ="), "{}", stdout(&o));

        let o = dexcube(&[command, misfit[0], misfit[1], "--out", out], "");
        assert_clean_failure(&o, 2, refusal);
        let missing = dir.join("missing");
        let o = dexcube(
            &[command, members[0], missing.to_str().unwrap(), "--out", out],
            "",
        );
        assert_clean_failure(&o, 2, "missing.json");
    }
}

/// `eval-stage --control-substeps` runs a policy at another control rate,
/// `--physics-spread` on varied physics and `--episode-steps` over another length, and each
/// says so; the policy's card is written only at the rate it was trained at, on the scene's
/// own physics, over the paper's episode.
#[test]
fn eval_stage_runs_a_policy_at_another_rate_physics_or_length_and_records_only_its_own() {
    let dir = std::env::temp_dir().join("dexcube-cli-eval-stage-rate");
    let (rot, layer) = (copy_policy("rot", &dir, "rot"), models().join("layer"));
    let eval = ["eval-stage", "rot", "--episodes", "1", "--threads", "1"];
    let rate = [
        "--rot-policy",
        rot.to_str().unwrap(),
        "--layer-policy",
        layer.to_str().unwrap(),
        "--control-substeps",
        "10",
    ];
    let card_before = std::fs::read_to_string(dir.join("rot.json")).unwrap();
    // Each way of running it: its flags, what the run says, and why --record refuses it.
    let ways: [(&[&str], &str, &str); 3] = [
        (
            &rate[4..],
            "acting every 10 substeps (200 steps an episode)",
            "at the rate it was trained at (20 substeps), not at 10",
        ),
        (
            &["--physics-spread", "0.3"],
            "seed 1000000, physics varied by spread 0.3, policy",
            "on the scene's own physics, not under --physics-spread 0.3",
        ),
        (
            &["--episode-steps", "150"],
            "seed 1000000, 150 steps an episode, policy",
            "over the paper's episode, not over --episode-steps",
        ),
    ];
    for (flags, says, refused) in ways {
        let run = [&eval[..], &rate[..4], flags].concat();
        let o = dexcube(&run, "");
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(stdout(&o).contains(says), "{}", stdout(&o));
        let o = dexcube(&[&run[..], &["--record"]].concat(), "");
        assert_clean_failure(&o, 2, refused);
    }
    let o = dexcube(&[&eval[..], &["--episode-steps", "0"]].concat(), "");
    assert_clean_failure(&o, 2, "--episode-steps <N>");
    assert_eq!(
        std::fs::read_to_string(dir.join("rot.json")).unwrap(),
        card_before
    );
}

/// `distil` teaches one actor to act as the shipped Stage 1 ensemble does: it writes the
/// student as a single policy that eval-stage runs, and one row per DAgger round; bad
/// arguments and a missing teacher fail cleanly.
#[test]
fn distil_writes_a_single_student_eval_stage_runs_and_one_row_per_round() {
    let dir = fresh_dir("dexcube-cli-distil");
    let (rot, layer) = (models().join("rot"), models().join("layer"));
    let (rot, layer) = (rot.to_str().unwrap(), layer.to_str().unwrap());
    let out = dir.join("student");
    let out = out.to_str().unwrap();
    let distil = |rounds: &str, teacher: &str, more: &[&str]| {
        let common = [
            "distil",
            "rot",
            "--rot-policy",
            teacher,
            "--layer-policy",
            layer,
            "--out",
            out,
            "--rounds",
            rounds,
            "--episodes",
            "2",
            "--epochs",
            "1",
            "--threads",
            "1",
        ];
        dexcube(&[&common[..], more].concat(), "")
    };
    let o = distil("2", rot, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let card: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(format!("{out}.json")).unwrap()).unwrap();
    assert!(card.get("partners").is_none(), "the student is one actor");
    let metadata = &card["metadata"];
    assert!(
        metadata["label"]
            .as_str()
            .unwrap()
            .starts_with("distilled from ensemble of 3")
    );
    assert_eq!(metadata["environment"]["env"], "rot");
    let rounds = metadata["distillation"]["rounds"].as_array().unwrap();
    assert_eq!(rounds.len(), 2);
    assert_eq!(rounds[0]["acting"], "teacher");
    assert_eq!(rounds[1]["acting"], "student");
    assert!(rounds[1]["rows"].as_u64().unwrap() > rounds[0]["rows"].as_u64().unwrap());
    let csv = std::fs::read_to_string(dir.join("student-rounds.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "{csv}");
    let o = dexcube(
        &[
            "eval-stage",
            "rot",
            "--episodes",
            "2",
            "--threads",
            "1",
            "--rot-policy",
            out,
            "--layer-policy",
            layer,
        ],
        "",
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("/2 ="), "{}", stdout(&o));

    assert_clean_failure(
        &distil("0", rot, &[]),
        2,
        "--rounds, --episodes and --epochs",
    );
    let teacher_copy = copy_policy("rot", &dir, "teacher");
    let teacher_copy = teacher_copy.to_str().unwrap();
    let over_itself = [
        "--rot-policy",
        teacher_copy,
        "--layer-policy",
        layer,
        "--out",
        teacher_copy,
    ];
    let o = dexcube(&[&["distil", "rot"][..], &over_itself].concat(), "");
    assert_clean_failure(&o, 2, "is the teacher itself");
    let missing = dir.join("missing");
    assert_clean_failure(
        &distil("1", missing.to_str().unwrap(), &[]),
        2,
        "missing.json",
    );

    // Episodes may begin where the operator handed Stage 1 the cube; the card says so. A file
    // of the other stage's starts, or a share that is not one, is refused.
    let starts = |name: &str| {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../results/starts")
            .join(name)
            .to_str()
            .unwrap()
            .to_string()
    };
    let from =
        |file: &str, share: &str| distil("1", rot, &["--starts", file, "--start-share", share]);
    let o = from(&starts("starts-ens-train-seed1.safetensors"), "1");
    assert!(o.status.success(), "{}", stderr(&o));
    let card: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(format!("{out}.json")).unwrap()).unwrap();
    assert_eq!(card["metadata"]["start_share"], 1.0);
    assert!(
        card["metadata"]["command"]
            .as_str()
            .unwrap()
            .contains("--starts ")
    );
    let layer_starts = starts("layer-starts-ens-train-seed1.safetensors");
    assert_clean_failure(
        &from(&layer_starts, "0.5"),
        2,
        "holds layer starts, not rot's",
    );
    let o = from(&starts("starts-ens-train-seed1.safetensors"), "2");
    assert_clean_failure(&o, 2, "a share is a number from 0 to 1");
}

/// `eval-stage --video` writes the first episode as a video, one frame for its start and one
/// for each control step, and counts the episodes as it would without one.
#[test]
fn eval_stage_writes_a_video_of_its_first_episode() {
    let dir = fresh_dir("dexcube-cli-eval-stage-video");
    let video = dir.join("first.gif");
    let policies = shipped_policy_flags();
    let eval = [
        &["eval-stage", "layer", "--episodes", "2", "--threads", "1"][..],
        &policies.each_ref().map(String::as_str),
    ]
    .concat();
    let o = dexcube(
        &[&eval[..], &["--video", video.to_str().unwrap()]].concat(),
        "",
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&format!("wrote {} (101 frames)", video.display())),
        "{}",
        stderr(&o)
    );
    assert!(std::fs::read(&video).unwrap().starts_with(b"GIF89a"));
    let without = dexcube(&eval, "");
    assert_eq!(
        stdout(&o).lines().next(),
        stdout(&without).lines().next(),
        "the same count"
    );
}

/// Runs `eval-stage` on two episodes of `stage` from `seed` with the `[rot, layer]` policies,
/// in `dir`, and returns each episode's row less its last column, whether it was handed over,
/// and that column, with what the command printed.
fn two_episodes(
    dir: &std::path::Path,
    (stage, seed): (&str, &str),
    [rot, layer]: [&str; 2],
) -> (Vec<(String, String)>, String) {
    let args = [stage, "--episodes", "2", "--threads", "2", "--seed", seed];
    let policies = ["--rot-policy", rot, "--layer-policy", layer];
    let (text, printed) =
        eval_stage_csv(&dir.join("episodes.csv"), &[&args[..], &policies].concat());
    let split = |line: &str| {
        let (row, handed) = line.rsplit_once(',').unwrap();
        (row.to_string(), handed.to_string())
    };
    (text.lines().skip(1).map(split).collect(), printed)
}

/// Runs `handover` with `args` into `out`, checks that it succeeded saying `says`, and returns
/// `out` as the policy path to pass on.
fn handover_into(args: &[&str], out: &std::path::Path, says: &str) -> String {
    let out = out.to_str().unwrap();
    let o = dexcube(&[&["handover"][..], args, &["--out", out]].concat(), "");
    assert!(
        o.status.success() && stdout(&o).contains(says),
        "{}",
        stderr(&o)
    );
    out.to_string()
}

/// Runs `eval-stage` with `args` and `--episodes-csv csv`, checks that it succeeded, and
/// returns the CSV's text and what the command printed.
fn eval_stage_csv(csv: &std::path::Path, args: &[&str]) -> (String, String) {
    let args = [
        &["eval-stage"][..],
        args,
        &["--episodes-csv", csv.to_str().unwrap()],
    ]
    .concat();
    let o = dexcube(&args, "");
    assert!(o.status.success(), "{}", stderr(&o));
    (std::fs::read_to_string(csv).unwrap(), stdout(&o))
}

/// Runs `eval-stage` with `args` (the stage first, then where its episodes come from and any
/// other flags), the shipped policies and `--episodes-csv`, in a folder of its own named by
/// `run`, and returns the rows under the CSV's header (which it checks) and what the command
/// printed.
fn episode_rows(run: &str, args: &[&str]) -> (Vec<Vec<String>>, String) {
    let dir = fresh_dir(&format!("dexcube-cli-eval-stage-episodes-{run}"));
    let policies = shipped_policy_flags();
    let args = [
        args,
        &["--threads", "2"],
        &policies.each_ref().map(String::as_str),
    ]
    .concat();
    let (text, printed) = eval_stage_csv(&dir.join("episodes.csv"), &args);
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some(
            "episode,seed,ending,position_error,angle_error,square,turned_a_layer,longest_hold,\
             start_angle_error,first_at_goal,mean_frame_angle_error,handed_over"
        )
    );
    let rows = lines
        .map(|line| line.split(',').map(String::from).collect())
        .collect();
    (rows, printed)
}

/// `eval-stage --episodes-csv` writes one row per episode, in order, whose endings add up to
/// the count it prints, and whose errors agree with each ending: each begins a quarter turn
/// from its goal, and a success first met the test no later than its final hold began.
#[test]
fn eval_stage_writes_a_row_per_episode() {
    let (rows, printed) = episode_rows("layer", &["layer", "--episodes", "3", "--seed", "8000014"]);
    assert_eq!(rows.len(), 3);
    let mut successes = 0;
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(row[0], k.to_string());
        assert_eq!(row[1], (8_000_014 + k).to_string());
        let angle_error: f64 = row[4].parse().unwrap();
        let longest_hold: usize = row[7].parse().unwrap();
        let start_angle_error: f64 = row[8].parse().unwrap();
        assert!(
            (start_angle_error - std::f64::consts::FRAC_PI_2).abs() < 0.02,
            "{row:?}"
        );
        assert_eq!(row[10], "", "Stage 2's goal is no pose");
        if row[2] == "success" {
            successes += 1;
            assert!(angle_error < 0.1 && longest_hold >= 1, "{row:?}");
            let first_at_goal: usize = row[9].parse().unwrap();
            assert!(first_at_goal + longest_hold <= 101, "{row:?}");
        } else {
            assert!(angle_error >= 0.1 || row[2] == "dropped", "{row:?}");
        }
    }
    assert!(
        printed.contains(&format!(": {successes}/3 = ")),
        "{printed}"
    );
}

/// Stage 1's rows also give the final angle with the pose read from all eight cubelets: on
/// a cube left square it is within a few hundredths of DBL's.
#[test]
fn eval_stage_rows_give_stage1_the_whole_cubes_angle() {
    let (rows, _) = episode_rows("rot", &["rot", "--episodes", "2", "--seed", "1000000"]);
    assert_eq!(rows.len(), 2);
    for row in &rows {
        let (dbl, mean): (f64, f64) = (row[4].parse().unwrap(), row[10].parse().unwrap());
        if row[5] == "true" {
            assert!((dbl - mean).abs() < 0.05, "{row:?}");
        }
    }
}

/// `eval-stage --record-closest` keeps, for each Stage 1 miss that kept the cube, where it
/// came closest to its pose: one state for each such row of the episodes' CSV (not for the
/// successes or the drop among these episodes), marked failed, and each no further from the
/// pose than its episode ended. Stage 2, whose goal counts from the layer's start, is refused.
#[test]
fn eval_stage_records_where_stage1_misses_came_closest() {
    let dir = fresh_dir("dexcube-cli-closest");
    let file = dir.join("closest.safetensors");
    let file = file.to_str().unwrap();
    // Seed 14000000's first 12 episodes hold a drop and two misses of the angle.
    let (rows, printed) = episode_rows(
        "closest-fresh",
        &["rot", "--episodes", "12", "--seed", "14000000"],
    );
    let (recorded, said) = episode_rows(
        "closest-recorded",
        &[
            "rot",
            "--episodes",
            "12",
            "--seed",
            "14000000",
            "--record-closest",
            file,
        ],
    );
    assert_eq!(recorded, rows, "recording changes no episode");
    let misses: Vec<&Vec<String>> = rows
        .iter()
        .filter(|row| !["success", "dropped"].contains(&row[2].as_str()))
        .collect();
    assert!(
        !misses.is_empty() && rows.iter().any(|row| row[2] == "dropped"),
        "{printed}"
    );
    assert!(
        said.contains(&format!("recorded where the {} misses", misses.len())),
        "{said}"
    );
    let (replayed, said) = episode_rows("closest-replayed", &["rot", "--starts", file]);
    assert_eq!(replayed.len(), misses.len(), "{said}");
    assert!(
        said.contains(&format!("missed the pose: {}; ", misses.len())),
        "{said}"
    );
    for (start, miss) in replayed.iter().zip(&misses) {
        let began: f64 = start[8].parse().unwrap();
        let ended: f64 = miss[4].parse().unwrap();
        assert!(
            began <= ended,
            "{start:?} began further off than {miss:?} ended"
        );
    }
    let policies = shipped_policy_flags();
    let layer = [
        &[
            "eval-stage",
            "layer",
            "--episodes",
            "1",
            "--record-closest",
            file,
        ][..],
        &policies.each_ref().map(String::as_str),
    ]
    .concat();
    assert_clean_failure(
        &dexcube(&layer, ""),
        2,
        "--record-closest keeps Stage 1's states",
    );
}

/// `handover` writes an ensemble that `eval-stage` runs handing stalled episodes to a member:
/// at once (a patience of 0) it runs each episode as that member alone, never (a patience
/// longer than an episode) as the ensemble, and the CSV says which were handed over. Told to let
/// a member act first and never handing over, it runs as that member alone. A single policy
/// and a member the ensemble lacks are refused, and so is distilling it.
#[test]
fn an_ensemble_handing_over_runs_as_its_member_once_handed_over() {
    let dir = fresh_dir("dexcube-cli-handover");
    std::fs::create_dir_all(&dir).unwrap();
    let [rot, member, layer] = ["rot", "rot-td3-19", "layer"].map(|name| models().join(name));
    let [rot, member, layer] = [&rot, &member, &layer].map(|path| path.to_str().unwrap());
    // Handing over to `member` after `patience` steps, and `first` acting alone until then.
    let handing_after = |first: &[&str], member: &str, patience: &str| {
        let out = dir.join(format!("rot-hand-{}-{member}-{patience}", first.concat()));
        let args = [
            &[rot, "--member", member, "--patience", patience][..],
            first,
        ]
        .concat();
        handover_into(&args, &out, &format!("to member {member}"))
    };
    let handing = |patience: &str| handing_after(&[], "2", patience);
    let rows = |policy: &str| two_episodes(&dir, ("rot", "2000000"), [policy, layer]);
    let (alone, _) = rows(member);
    let (together, _) = rows(rot);
    assert_ne!(
        alone, together,
        "the member acts otherwise than the ensemble"
    );
    let (at_once, printed) = rows(&handing("0"));
    assert!(
        printed.contains("handed over to member 2 in 2 episodes"),
        "{printed}"
    );
    let episodes =
        |rows: &[(String, String)]| rows.iter().map(|(row, _)| row.clone()).collect::<Vec<_>>();
    let all_handed =
        |rows: &[(String, String)], to: &str| rows.iter().all(|(_, handed)| handed == to);
    assert!(all_handed(&at_once, "true") && all_handed(&alone, "false"));
    assert_eq!(episodes(&at_once), episodes(&alone));
    let (never, printed) = rows(&handing("1000"));
    assert!(
        printed.contains("handed over to member 2 in 0 episodes"),
        "{printed}"
    );
    assert_eq!(never, together);
    let (first_alone, _) = rows(&handing_after(&["--first", "2"], "0", "1000"));
    assert_eq!(
        first_alone, alone,
        "member 2 acting first, never handing over"
    );
    let (teacher, out) = (handing("5"), dir.join("student"));
    let distil = [
        &["distil", "rot", "--rot-policy", &teacher][..],
        &["--layer-policy", layer, "--out", out.to_str().unwrap()],
    ]
    .concat();
    assert_clean_failure(
        &dexcube(&distil, ""),
        2,
        "hands stalled episodes to a member",
    );
    for (policy, member, says) in [
        (
            member,
            "0",
            "a single policy, with no member to hand over to",
        ),
        (rot, "3", "it has 3 members (0 to 2), not a member 3"),
    ] {
        let out = dir.join("refused");
        let args = [
            &["handover", policy, "--member", member][..],
            &["--out", out.to_str().unwrap()],
        ]
        .concat();
        assert_clean_failure(&dexcube(&args, ""), 2, says);
    }
}

/// `handover --let-go N` on a single Stage 2 policy: never handed over it runs every episode as
/// the policy alone; handed over at once and letting go for the whole episode, the hand only
/// ever takes the neutral action, so no layer turns.
#[test]
fn a_policy_letting_go_takes_the_neutral_action_then_tries_again() {
    let dir = fresh_dir("dexcube-cli-let-go");
    let [rot, layer] = ["rot", "layer"].map(|name| models().join(name));
    let [rot, layer] = [&rot, &layer].map(|path| path.to_str().unwrap());
    let letting_go = |patience: &str, steps: &str| {
        let out = dir.join(format!("layer-let-go-{patience}-{steps}"));
        let args = [
            layer,
            "--member",
            "0",
            "--patience",
            patience,
            "--let-go",
            steps,
        ];
        handover_into(&args, &out, &format!("letting go for {steps} steps"))
    };
    let rows = |policy: &str| {
        let (rows, _) = two_episodes(&dir, ("layer", "13000000"), [rot, policy]);
        rows.into_iter().map(|(row, _)| row).collect::<Vec<_>>()
    };
    assert_eq!(rows(&letting_go("1000", "5")), rows(layer));
    for row in rows(&letting_go("0", "100")) {
        let ending = row.split(',').nth(2).unwrap();
        assert_eq!(ending, "never_turned", "{row}");
    }
}

/// `eval-stage --record-handovers` keeps the state where an ensemble handed each episode to its
/// member, marked failed where the episode failed: handed over at once, the member alone run
/// from those states ends every episode as it ends from the fresh placements. A policy that
/// hands none over, and Stage 2, are refused.
#[test]
fn eval_stage_records_where_an_ensemble_hands_over() {
    let dir = fresh_dir("dexcube-cli-record-handovers");
    std::fs::create_dir_all(&dir).unwrap();
    let [rot, member, layer] = ["rot", "rot-td3-19", "layer"].map(|name| models().join(name));
    let [rot, member, layer] = [&rot, &member, &layer].map(|path| path.to_str().unwrap());
    let (at_once, file) = (dir.join("rot-hand-0"), dir.join("handovers.safetensors"));
    let args = [rot, "--member", "2", "--patience", "0"];
    let at_once = handover_into(&args, &at_once, "to member 2");
    let (at_once, file) = (at_once.as_str(), file.to_str().unwrap());
    let run = |policy: &str, from: &[&str], csv: &str| {
        let args = [
            &["rot", "--episodes", "3", "--threads", "2"][..],
            from,
            &["--rot-policy", policy, "--layer-policy", layer],
        ]
        .concat();
        let (text, printed) = eval_stage_csv(&dir.join(csv), &args);
        let endings: Vec<String> = text
            .lines()
            .skip(1)
            .map(|line| line.splitn(3, ',').nth(2).unwrap().to_string())
            .collect();
        (endings, printed)
    };
    let fresh = ["--seed", "2000000"];
    let (handed, printed) = run(
        at_once,
        &[&fresh[..], &["--record-handovers", file]].concat(),
        "a.csv",
    );
    let failures = handed
        .iter()
        .filter(|row| !row.starts_with("success"))
        .count();
    assert!(
        printed.contains(&format!(
            "the 3 episodes handed over ({failures} of them failed)"
        )),
        "{printed}"
    );
    let (replayed, printed) = run(member, &["--starts", file], "b.csv");
    assert!(
        printed.contains(&format!("dropped the cube or missed the pose: {failures};")),
        "{printed}"
    );
    let (alone, _) = run(member, &fresh, "c.csv");
    // Less the last column, which says whether the episode was handed over.
    let less_last = |rows: &[String]| -> Vec<String> {
        rows.iter()
            .map(|row| row.rsplit_once(',').unwrap().0.to_string())
            .collect()
    };
    assert_eq!(less_last(&replayed), less_last(&alone));
    assert_eq!(less_last(&handed), less_last(&alone));
    let refused = |stage: &str, policy: &str| {
        let args = [
            &[
                "eval-stage",
                stage,
                "--episodes",
                "1",
                "--rot-policy",
                policy,
            ][..],
            &["--layer-policy", layer, "--record-handovers", file],
        ]
        .concat();
        dexcube(&args, "")
    };
    assert_clean_failure(&refused("rot", rot), 2, "hands none over");
    assert_clean_failure(
        &refused("layer", at_once),
        2,
        "--record-handovers keeps Stage 1's states",
    );
}

/// `eval-stage --record-strays` keeps, for each Stage 1 episode whose cube strays past the
/// radius, the state where it first did, marked failed where the episode failed: with a radius
/// every cube passes at once, every episode; with one no cube reaches, none. Stage 2 and a
/// radius that is not a positive distance are refused.
#[test]
fn eval_stage_records_where_the_cube_strays() {
    let dir = fresh_dir("dexcube-cli-record-strays");
    let [rot, layer] = ["rot", "layer"].map(|name| models().join(name));
    let [rot, layer] = [&rot, &layer].map(|path| path.to_str().unwrap());
    let file = dir.join("strays.safetensors");
    let file = file.to_str().unwrap();
    // The policies and the recording, with the radius.
    let recording = |radius: &'static str| {
        [
            "--rot-policy",
            rot,
            "--layer-policy",
            layer,
            "--record-strays",
            file,
            "--stray-radius",
            radius,
        ]
    };
    let run = |radius: &'static str| {
        let fresh = [
            "rot",
            "--episodes",
            "3",
            "--threads",
            "2",
            "--seed",
            "2000000",
        ];
        let args = [&fresh[..], &recording(radius)].concat();
        eval_stage_csv(&dir.join(format!("{radius}.csv")), &args)
    };
    let (text, printed) = run("0.0001");
    let failures = (text.lines().skip(1))
        .filter(|row| row.split(',').nth(2) != Some("success"))
        .count();
    let says = format!(
        "the 3 episodes whose cube strayed more than 0.0001 m from its goal's position ({failures} of them failed)"
    );
    assert!(printed.contains(&says), "{printed}");
    let (_, printed) = run("1");
    assert!(
        printed.contains("the 0 episodes whose cube strayed more than 1 m"),
        "{printed}"
    );
    let refused = |stage: &str, radius: &'static str| {
        let args = [
            &["eval-stage", stage, "--episodes", "1"][..],
            &recording(radius),
        ]
        .concat();
        dexcube(&args, "")
    };
    assert_clean_failure(
        &refused("layer", "0.05"),
        2,
        "--record-strays keeps Stage 1's states",
    );
    assert_clean_failure(
        &refused("rot", "0"),
        2,
        "--stray-radius must be a distance in metres above 0",
    );
}

/// `goal-lead` writes a policy that `eval-stage` runs shown its goal led on, which a single
/// episode tells from the policy it was made from; bad settings and combining it are refused.
#[test]
fn a_policy_led_on_runs_on_the_goal_led_on() {
    let dir = fresh_dir("dexcube-cli-goal-lead");
    std::fs::create_dir_all(&dir).unwrap();
    let (rot, layer) = (models().join("rot"), models().join("layer"));
    let (rot, layer) = (rot.to_str().unwrap(), layer.to_str().unwrap());
    let led = dir.join("layer-led");
    let led = led.to_str().unwrap();
    let o = dexcube(&["goal-lead", layer, "--share", "0.5", "--out", led], "");
    assert!(
        o.status.success() && stdout(&o).contains("led on by 0.5 within 0.5 rad"),
        "{}",
        stderr(&o)
    );
    let row = |policy: &str| {
        let args = [
            &["layer", "--episodes", "1", "--threads", "1"][..],
            // An episode that turns the layer, so that it comes within the lead's reach.
            &["--seed", "8000016"],
            &["--rot-policy", rot, "--layer-policy", policy],
        ]
        .concat();
        eval_stage_csv(&dir.join("episodes.csv"), &args).0
    };
    assert_ne!(row(layer), row(led), "the same episode, acted otherwise");
    for (flags, says) in [
        (&["--share", "0"][..], "--share must be a positive number"),
        (
            &["--share", "0.5", "--within", "4"],
            "--within must be an angle",
        ),
    ] {
        let args = [&["goal-lead", layer, "--out", led][..], flags].concat();
        assert_clean_failure(&dexcube(&args, ""), 2, says);
    }
    let joined = dexcube(&["ensemble", led, layer, "--out", led], "");
    assert_clean_failure(&joined, 2, "shown its goal led on (by 0.5 within 0.5 rad)");
}

/// `nearest-frame` writes a Stage 1 policy that `eval-stage` runs shown the cube in the frame
/// nearest its goal, which a single episode tells from the policy it was made from; a Stage 2
/// policy, a second relabelling and distilling it are refused cleanly.
#[test]
fn a_stage_1_policy_runs_in_the_frame_nearest_its_goal() {
    let dir = fresh_dir("dexcube-cli-nearest-frame");
    std::fs::create_dir_all(&dir).unwrap();
    let (rot, layer) = (models().join("rot"), models().join("layer"));
    let (rot, layer) = (rot.to_str().unwrap(), layer.to_str().unwrap());
    let nearest = dir.join("rot-nearest");
    let nearest = nearest.to_str().unwrap();
    let o = dexcube(&["nearest-frame", rot, "--out", nearest], "");
    assert!(
        o.status.success() && stdout(&o).contains("shown the cube in the frame nearest its goal"),
        "{}",
        stderr(&o)
    );
    let row = |policy: &str| {
        let args = [
            &[
                "rot",
                "--episodes",
                "1",
                "--threads",
                "1",
                "--seed",
                "2000000",
            ][..],
            &["--rot-policy", policy, "--layer-policy", layer],
        ]
        .concat();
        eval_stage_csv(&dir.join("episodes.csv"), &args).0
    };
    assert_ne!(
        row(rot),
        row(nearest),
        "the same placement, acted otherwise"
    );
    let refused = dir.join("refused");
    let refused = refused.to_str().unwrap();
    for (policy, says) in [
        (layer, "not a pose (Stage 1's 7 or 8)"),
        (nearest, "in the frame nearest its goal already"),
    ] {
        let o = dexcube(&["nearest-frame", policy, "--out", refused], "");
        assert_clean_failure(&o, 2, says);
    }
    let distil = [
        &["distil", "rot", "--rot-policy", nearest][..],
        &["--layer-policy", layer, "--out", refused],
    ]
    .concat();
    assert_clean_failure(
        &dexcube(&distil, ""),
        2,
        "shown the cube in the frame nearest its goal",
    );
}

/// `start-gesture --member 1` on an ensemble of `layer` and another Stage 2, handing over with
/// `--first 0 --member 0 --let-go 10`, acts episode for episode as the other policy with the
/// same handover and gesture where the gesture is made, and as `layer` with them elsewhere
/// (`models/layer-gesture`'s making, with a specialist for its gesture's episodes); a member
/// the ensemble lacks is refused cleanly.
fn a_specialist_acts_alone_where_the_gesture_is_made(
    dir: &std::path::Path,
    [rot, layer]: [&str; 2],
) {
    let other = models().join("layer-w512-19");
    let other = other.to_str().unwrap();
    let path = |name: &str| dir.join(name);
    let joined = dexcube(
        &[
            "ensemble",
            layer,
            other,
            "--out",
            path("pair").to_str().unwrap(),
        ],
        "",
    );
    assert!(joined.status.success(), "{}", stderr(&joined));
    let let_go = |from: &str, first: &[&str], name: &str| {
        let args = [&[from][..], first, &["--member", "0", "--let-go", "10"]].concat();
        handover_into(&args, &path(name), "letting go for 10 steps first")
    };
    let pair = path("pair");
    let handing = [
        let_go(pair.to_str().unwrap(), &["--first", "0"], "pair-letgo"),
        let_go(layer, &[], "layer-letgo"),
        let_go(other, &[], "other-letgo"),
    ];
    let gesture = |from: &str, member: &[&str], name: &str| {
        let args = ["--actuators", "3,6,9,13", "--action", "-1", "--steps", "5"];
        let out = path(name);
        let flags = [
            &["start-gesture", from][..],
            &args,
            member,
            &["--out", out.to_str().unwrap()],
        ];
        (
            dexcube(&flags.concat(), ""),
            out.to_str().unwrap().to_string(),
        )
    };
    let rows = |from: &str, member: &[&str], name: &str| {
        let (o, policy) = gesture(from, member, name);
        assert!(o.status.success(), "{}", stderr(&o));
        let args = [
            "layer",
            "--episodes",
            "8",
            "--threads",
            "2",
            "--seed",
            "13000000",
        ];
        let policies = ["--rot-policy", rot, "--layer-policy", &policy];
        let (text, printed) =
            eval_stage_csv(&dir.join("episodes.csv"), &[&args[..], &policies].concat());
        let rows: Vec<String> = text.lines().skip(1).map(str::to_string).collect();
        (rows, printed)
    };
    let (mine, printed) = rows(&handing[0], &["--member", "1"], "specialist");
    let (elsewhere, _) = rows(&handing[1], &[], "layer-gesture");
    let (where_made, _) = rows(&handing[2], &[], "other-gesture");
    let made = (0..8).filter(|&k| mine[k] != elsewhere[k]).count();
    assert!(
        printed.contains(&format!("began with the start gesture in {made} episodes"))
            && (1..8).contains(&made),
        "{printed}"
    );
    for k in 0..8 {
        assert!(
            mine[k] == elsewhere[k] || mine[k] == where_made[k],
            "episode {k}: {}",
            mine[k]
        );
    }
    let (o, _) = gesture(&handing[0], &["--member", "2"], "no-member");
    assert_clean_failure(&o, 2, "it has 2 member(s) (0 to 1), not a member 2");
}

/// `start-gesture` writes a policy whose card names the gesture and where the cube scene's
/// resting point lies, and `eval-stage` counts the episodes that began with it; `distil`
/// refuses it as a teacher, and a gesture the hand cannot make, an action past the actuators'
/// range, a second gesture and a missing policy fail cleanly.
#[test]
fn a_start_gesture_is_written_counted_and_refused_cleanly() {
    let dir = fresh_dir("dexcube-cli-start-gesture");
    let [rot, layer] = ["rot", "layer"].map(|name| models().join(name));
    let [rot, layer] = [&rot, &layer].map(|path| path.to_str().unwrap());
    let out = dir.join("layer-gesture");
    let out = out.to_str().unwrap();
    let gesture = |from: &str, actuators: &str, action: &str| {
        let args = ["--actuators", actuators, "--action", action, "--steps", "5"];
        dexcube(
            &[&["start-gesture", from][..], &args, &["--out", out]].concat(),
            "",
        )
    };
    let o = gesture(layer, "3,6,9,13", "-1");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("actuators 3,6,9,13 at -1 for the first 5 steps"));
    let card: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(format!("{out}.json")).unwrap()).unwrap();
    let below_y = card["start_gesture"]["below_y"].as_f64().unwrap();
    assert!(
        (below_y - 0.8766).abs() < 1e-3,
        "the palm's resting point: {below_y}"
    );
    assert_eq!(card["metadata"]["start_gesture"], layer);
    let (_, printed) = two_episodes(&dir, ("layer", "13000000"), [rot, out]);
    assert!(
        printed.contains("began with the start gesture in"),
        "{printed}"
    );
    let student = dir.join("student");
    let distil = [
        &[
            "distil",
            "layer",
            "--rot-policy",
            rot,
            "--layer-policy",
            out,
        ][..],
        &["--out", student.to_str().unwrap()],
    ]
    .concat();
    assert_clean_failure(&dexcube(&distil, ""), 2, "makes a start gesture");
    after_gesture_starts_are_where_the_policy_first_acts(&dir, [rot, layer, out]);
    a_specialist_acts_alone_where_the_gesture_is_made(&dir, [rot, layer]);
    for (from, actuators, action, says) in [
        (layer, "3,20", "-1", "not an actuator 20"),
        (layer, "3", "1.5", "an action is between -1 and 1, not 1.5"),
        (out, "3", "-1", "makes a start gesture already"),
        ("no/such/policy", "3", "-1", "no/such/policy.json"),
    ] {
        assert_clean_failure(&gesture(from, actuators, action), 2, says);
    }
}
