//! The optimal solvers against published counts and against each other.

use std::sync::OnceLock;

use dexcube_cube::coord::Metric;
use dexcube_cube::{
    DistanceTable, Facelets, IdaStar, Move, POSITIONS, Position, Solver, parse_moves,
};
use proptest::prelude::*;

fn table() -> &'static DistanceTable {
    static TABLE: OnceLock<DistanceTable> = OnceLock::new();
    TABLE.get_or_init(DistanceTable::build)
}

fn ida() -> &'static IdaStar {
    static IDA: OnceLock<IdaStar> = OnceLock::new();
    IDA.get_or_init(IdaStar::new)
}

#[test]
fn quarter_turn_histogram_matches_the_published_counts() {
    let expected = [
        1, 6, 27, 120, 534, 2256, 8969, 33058, 114149, 360508, 930588, 1350852, 782536, 90280, 276,
    ];
    assert_eq!(table().histogram(), expected);
    assert_eq!(expected.iter().sum::<u64>(), POSITIONS as u64);
    assert_eq!(table().diameter(), 14);
}

#[test]
fn half_turn_histogram_matches_the_published_counts() {
    let expected = [
        1, 9, 54, 321, 1847, 9992, 50136, 227536, 870072, 1887748, 623800, 2644,
    ];
    assert_eq!(DistanceTable::build_in(Metric::Half).histogram(), expected);
}

/// Checks that `solution` solves `cube` with exactly `distance` quarter turns of U, R, F.
fn assert_solves(cube: &Facelets, solution: &[Move], distance: usize) {
    assert_eq!(solution.len(), distance, "{cube}: not optimal");
    assert!(
        solution.iter().all(|m| m.quarters != 2),
        "{cube}: half turn in a QTM answer"
    );
    assert!(
        cube.apply_all(solution).is_solved(),
        "{cube}: solution does not solve it"
    );
}

#[test]
fn table_and_ida_agree_and_solve_thousands_of_positions() {
    // Every 1223rd position: 3005 cubes spread over all distances.
    for index in (0..POSITIONS).step_by(1223) {
        let position = Position::from_index(index);
        let cube = position.to_facelets();
        let distance = table().distance(&position);
        assert_solves(&cube, &table().solve(&position), distance);
        assert_solves(&cube, &ida().solve(&position), distance);
    }
}

#[test]
fn every_position_at_distance_14_is_solved_optimally_by_both() {
    for index in table().indices_at(14) {
        let position = Position::from_index(index);
        assert_solves(&position.to_facelets(), &ida().solve(&position), 14);
    }
}

#[test]
fn all_optimal_solutions_are_distinct_optimal_and_complete() {
    let u2 = Facelets::SOLVED.apply_all(&parse_moves("U2").unwrap());
    let all: Vec<String> = table()
        .all_optimal(&Position::of(&u2))
        .iter()
        .map(|s| dexcube_cube::format_moves(s))
        .collect();
    assert_eq!(all, ["U U", "U' U'"]);
    assert!(table().all_optimal(&Position::SOLVED) == vec![Vec::<Move>::new()]);
    for index in (0..POSITIONS).step_by(104_729) {
        let position = Position::from_index(index);
        let cube = position.to_facelets();
        let all = table().all_optimal(&position);
        let distance = table().distance(&position);
        assert!(all.contains(&table().solve(&position)));
        let mut distinct = all.clone();
        distinct.sort_by_key(|s| dexcube_cube::format_moves(s));
        distinct.dedup();
        assert_eq!(distinct.len(), all.len());
        for solution in &all {
            assert_solves(&cube, solution, distance);
        }
    }
}

#[test]
fn the_cheapest_optimal_solution_is_the_least_costly_of_all_optimal_ones() {
    // A hand's price: a clockwise quarter turn is three counter-clockwise ones, and a move
    // on another face than the last one needs the cube re-posed first.
    let price = |before: Option<Move>, m: Move| {
        let turns = if m.quarters == 3 { 1 } else { 3 };
        turns + u32::from(before.is_none_or(|b| b.face != m.face))
    };
    let total = |solution: &[Move]| {
        (0..solution.len())
            .map(|i| price(i.checked_sub(1).map(|j| solution[j]), solution[i]))
            .sum::<u32>()
    };
    let u2 = Facelets::SOLVED.apply_all(&parse_moves("U2").unwrap());
    let cheapest = table().cheapest_optimal(&Position::of(&u2), price);
    assert_eq!(dexcube_cube::format_moves(&cheapest), "U' U'");
    assert!(
        table()
            .cheapest_optimal(&Position::SOLVED, price)
            .is_empty()
    );
    let mut saved = 0;
    for index in (0..POSITIONS).step_by(104_729) {
        let position = Position::from_index(index);
        let all = table().all_optimal(&position);
        let cheapest = table().cheapest_optimal(&position, price);
        assert!(all.contains(&cheapest), "optimal");
        assert_eq!(
            total(&cheapest),
            all.iter().map(|s| total(s)).min().unwrap(),
            "least costly"
        );
        saved += total(&table().solve(&position)) - total(&cheapest);
    }
    assert!(
        saved > 0,
        "the first optimal solution is often not the cheapest"
    );
}

/// Whole-cube turns, each made of two opposite face turns.
const ROTATIONS: [&str; 3] = ["R L'", "U D'", "F B'"];

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    /// Random scrambles using all 18 moves, then a random whole-cube orientation: the answer,
    /// applied in the cube's own frame, solves it, no longer than the scramble.
    #[test]
    fn scrambles_in_any_orientation_are_solved_in_place(
        scramble in prop::collection::vec((0usize..6, 1u8..4), 0..30),
        turns in prop::collection::vec(0usize..3, 0..6),
    ) {
        let moves: Vec<Move> = scramble
            .iter()
            .map(|&(face, q)| Move::new(dexcube_cube::Face::ALL[face], q))
            .collect();
        let mut cube = Facelets::SOLVED.apply_all(&moves);
        for t in turns {
            cube = cube.apply_all(&parse_moves(ROTATIONS[t]).unwrap());
        }
        let reparsed = Facelets::parse(&cube.to_string()).unwrap();
        prop_assert_eq!(reparsed, cube);
        let position = Position::of(&cube);
        let solution = table().solve(&position);
        let qtm: usize = moves.iter().map(|m| m.quarter_turn_length()).sum();
        prop_assert!(solution.len() <= qtm);
        prop_assert!(cube.apply_all(&solution).is_solved());
        prop_assert_eq!(ida().solve(&position).len(), solution.len());
    }
}
