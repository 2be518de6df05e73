//! What the hand's plans need, per move distance, over Table I's scrambles: Stage 1 runs,
//! Stage 2 turns and quarter turns for the cheapest optimal plan (the operator's default) and
//! for the cheapest plan of any length with a Stage 1 priced PRICE turns (`--stage1-price`).
//! No physics: it counts what each plan asks of perfect stages, with U up at the start and
//! the first move priced blind, as the operator does by default.
//!
//! `cargo run --release -p dexcube-operator --example plan_costs -- [PRICE] [SEED]`
//! (defaults 5 and 0, Table I's seed).

use dexcube_cube::{CostTable, DistanceTable, Face, Move, Position, scrambles_at_distance};
use dexcube_operator::{hand_cost, hand_price, move_plan};

/// (Stage 1 runs, Stage 2 turns) of `plan`, starting with U up.
fn needs(plan: &[Move]) -> (usize, usize) {
    let mut up = Face::U;
    let (mut stage1, mut turns) = (0, 0);
    for &m in plan {
        let (face, n) = move_plan(m);
        stage1 += usize::from(face != up);
        turns += n;
        up = face;
    }
    (stage1, turns)
}

fn main() {
    let mut args = std::env::args().skip(1).map(|a| a.parse::<u64>());
    let price = args.next().and_then(Result::ok).unwrap_or(5) as u32;
    let seed = args.next().and_then(Result::ok).unwrap_or(0);
    let table = DistanceTable::build();
    let costs = CostTable::build(hand_price(price));
    println!("Stage 1 priced {price} turns, 100 scrambles per distance, seed {seed}");
    println!(
        "| move distance | Stage 1 runs, optimal / any length | Stage 2 turns | quarter turns |"
    );
    println!("|---|---|---|---|");
    for distance in 1..=14 {
        let mut sums = [0usize; 6];
        let scrambles = scrambles_at_distance(&table, distance, 100, seed);
        for scramble in &scrambles {
            let position = Position::of(&scramble.facelets);
            let optimal = table.cheapest_optimal(&position, hand_cost(None));
            let any = costs.cheapest(&position, None);
            for (k, plan) in [optimal, any].iter().enumerate() {
                let (stage1, turns) = needs(plan);
                sums[k] += stage1;
                sums[2 + k] += turns;
                sums[4 + k] += plan.len();
            }
        }
        let mean = |k: usize| sums[k] as f64 / scrambles.len() as f64;
        println!(
            "| {distance} | {:.2} / {:.2} | {:.2} / {:.2} | {:.2} / {:.2} |",
            mean(0),
            mean(1),
            mean(2),
            mean(3),
            mean(4),
            mean(5)
        );
    }
}
