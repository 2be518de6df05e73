//! Scrambles drawn at an exact move distance: right distance, reproducible, duplicates as
//! documented.

use std::collections::HashMap;

use dexcube_cube::{DistanceTable, Facelets, Position, scrambles_at_distance};

#[test]
fn scrambles_lie_at_their_distance_and_their_moves_make_them() {
    let table = DistanceTable::build();
    for d in 0..=14 {
        let scrambles = scrambles_at_distance(&table, d, 20, 7);
        assert_eq!(scrambles.len(), 20);
        for s in &scrambles {
            assert_eq!(table.distance(&Position::of(&s.facelets)), d);
            assert_eq!(s.moves.len(), d);
            assert_eq!(Facelets::SOLVED.apply_all(&s.moves), s.facelets);
        }
    }
    assert!(scrambles_at_distance(&table, 15, 3, 0).is_empty());
}

#[test]
fn same_seed_same_cubes_and_smaller_counts_are_prefixes() {
    let table = DistanceTable::build();
    let a = scrambles_at_distance(&table, 9, 100, 42);
    assert_eq!(a, scrambles_at_distance(&table, 9, 100, 42));
    assert_eq!(a[..30], scrambles_at_distance(&table, 9, 30, 42)[..]);
    assert_ne!(a, scrambles_at_distance(&table, 9, 100, 43));
}

#[test]
fn positions_are_distinct_until_they_run_out_then_evenly_repeated() {
    let table = DistanceTable::build();
    let at_14 = scrambles_at_distance(&table, 14, 276, 1);
    let mut seen: Vec<String> = at_14.iter().map(|s| s.facelets.to_string()).collect();
    seen.sort();
    seen.dedup();
    assert_eq!(
        seen.len(),
        276,
        "all 276 positions at distance 14, once each"
    );

    let at_1 = scrambles_at_distance(&table, 1, 100, 1);
    let mut counts: HashMap<String, usize> = HashMap::new();
    for s in &at_1 {
        *counts.entry(s.facelets.to_string()).or_default() += 1;
    }
    assert_eq!(counts.len(), 6);
    assert!(counts.values().all(|&c| c == 16 || c == 17), "{counts:?}");
}

#[test]
fn the_first_draw_is_uniform_over_seeds() {
    // 27 positions at distance 2 and 2700 seeds: about 100 each (binomial sd ~ 9.8).
    let table = DistanceTable::build();
    let mut counts: HashMap<String, usize> = HashMap::new();
    for seed in 0..2700 {
        let first = scrambles_at_distance(&table, 2, 1, seed).remove(0);
        *counts.entry(first.facelets.to_string()).or_default() += 1;
    }
    assert_eq!(counts.len(), 27);
    assert!(
        counts.values().all(|&c| (55..=145).contains(&c)),
        "{counts:?}"
    );
}
