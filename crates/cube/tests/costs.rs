//! The cost table's solutions of any length against the distance table and an exhaustive
//! search.

use std::sync::OnceLock;

use dexcube_cube::{
    CostTable, DistanceTable, Move, POSITIONS, Position, format_moves, scrambles_at_distance,
};

fn table() -> &'static DistanceTable {
    static TABLE: OnceLock<DistanceTable> = OnceLock::new();
    TABLE.get_or_init(DistanceTable::build)
}

/// A hand's price: a clockwise quarter turn is three counter-clockwise ones, and a move about
/// another axis than the last needs the cube re-posed first, which costs `repose`.
fn hand(repose: u32) -> impl Fn(Option<usize>, Move) -> u32 + Copy {
    move |before, m| {
        let turns = if m.quarters == 3 { 1 } else { 3 };
        turns + repose * u32::from(before != Some(m.face.axis()))
    }
}

/// What `solution` costs at `price`, the last move before it having turned about `before`.
fn total(
    price: impl Fn(Option<usize>, Move) -> u32,
    mut before: Option<usize>,
    solution: &[Move],
) -> u32 {
    solution
        .iter()
        .map(|&m| {
            let p = price(before, m);
            before = Some(m.face.axis());
            p
        })
        .sum()
}

fn solves(position: &Position, solution: &[Move]) -> bool {
    solution
        .iter()
        .fold(*position, |p, &m| p.apply(m))
        .is_solved()
}

fn sample() -> impl Iterator<Item = Position> {
    (0..POSITIONS).step_by(91_813).map(Position::from_index)
}

#[test]
fn with_every_move_at_one_the_cheapest_solutions_are_the_optimal_ones() {
    let costs = CostTable::build(|_, _| 1);
    assert!(costs.cheapest(&Position::SOLVED, None).is_empty());
    for position in sample() {
        let solution = costs.cheapest(&position, None);
        assert!(solves(&position, &solution));
        assert_eq!(solution.len(), table().distance(&position));
        assert_eq!(costs.cost(&position, Some(0)) as usize, solution.len());
    }
}

#[test]
fn a_hands_cheapest_plan_may_be_longer_than_optimal_and_is_never_dearer() {
    let price = hand(5);
    let costs = CostTable::build(price);
    let (mut cheaper, mut longer) = (0, 0);
    for position in sample() {
        for up in [None, Some(0), Some(1), Some(2)] {
            let solution = costs.cheapest(&position, up);
            assert!(solves(&position, &solution));
            let paid = |s: &[Move]| total(price, up, s);
            assert_eq!(
                paid(&solution),
                costs.cost(&position, up),
                "priced as built"
            );
            let optimal = table().cheapest_optimal(&position, |before, m| {
                price(before.map(|b| b.face.axis()).or(up), m)
            });
            assert!(paid(&solution) <= paid(&optimal), "never dearer");
            cheaper += usize::from(paid(&solution) < paid(&optimal));
            longer += usize::from(solution.len() > table().distance(&position));
        }
    }
    assert!(cheaper > 0 && longer > 0, "some plans gain by being longer");
}

/// Whether some move sequence that costs less than `budget`, pruned by the distance still to go
/// (each move costs at least 1), solves `position`.
fn solved_within(
    position: Position,
    before: Option<usize>,
    budget: u32,
    price: &impl Fn(Option<usize>, Move) -> u32,
) -> bool {
    if position.is_solved() {
        return true;
    }
    if table().distance(&position) as u32 >= budget {
        return false;
    }
    Move::QUARTER_TURNS[..]
        .iter()
        .filter(|m| matches!(m.face.letter(), 'U' | 'R' | 'F'))
        .any(|&m| {
            let p = price(before, m);
            p < budget && solved_within(position.apply(m), Some(m.face.axis()), budget - p, price)
        })
}

#[test]
fn no_sequence_is_cheaper_than_the_tables_least_cost() {
    let price = hand(2);
    let costs = CostTable::build(price);
    for distance in 1..=4 {
        for scramble in scrambles_at_distance(table(), distance, 5, 7) {
            let position = Position::of(&scramble.facelets);
            for up in [None, Some(0), Some(1), Some(2)] {
                let least = costs.cost(&position, up);
                let name = format_moves(&scramble.moves);
                assert!(
                    !solved_within(position, up, least, &price),
                    "{name}: cheaper"
                );
                assert!(
                    solved_within(position, up, least + 1, &price),
                    "{name}: as cheap"
                );
            }
        }
    }
}
