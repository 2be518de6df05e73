//! Unit quaternions (w, x, y, z) and the 24 rotations that map a cube onto itself.

/// A rotation as a unit quaternion `[w, x, y, z]`, MuJoCo's order.
pub type Quat = [f64; 4];

pub const IDENTITY: Quat = [1.0, 0.0, 0.0, 0.0];

/// The rotation `a` after `b` (`a * b`).
pub fn mul(a: &Quat, b: &Quat) -> Quat {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

pub fn conj(q: &Quat) -> Quat {
    [q[0], -q[1], -q[2], -q[3]]
}

pub fn normalise(q: &Quat) -> Quat {
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    q.map(|x| x / n)
}

/// Rotation by `angle` radians about the unit vector `axis`.
pub fn about(axis: [f64; 3], angle: f64) -> Quat {
    let (s, c) = (angle / 2.0).sin_cos();
    [c, axis[0] * s, axis[1] * s, axis[2] * s]
}

/// `v` rotated by `q`.
pub fn rotate(q: &Quat, v: [f64; 3]) -> [f64; 3] {
    let p = mul(&mul(q, &[0.0, v[0], v[1], v[2]]), &conj(q));
    [p[1], p[2], p[3]]
}

/// The angle of the rotation taking `a` to `b`, in [0, π]: 2·arccos(|⟨a, b⟩|).
pub fn angle_between(a: &Quat, b: &Quat) -> f64 {
    let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    2.0 * dot.abs().min(1.0).acos()
}

/// The signed angle of `q`'s rotation about the unit `axis` (its swing removed), in (-π, π].
pub fn twist_about(q: &Quat, axis: [f64; 3]) -> f64 {
    let along = q[1] * axis[0] + q[2] * axis[1] + q[3] * axis[2];
    2.0 * along.atan2(q[0])
}

/// The 24 proper rotations of a cube, the identity first.
pub fn cube_rotations() -> [Quat; 24] {
    let h = std::f64::consts::FRAC_PI_2;
    let mut all = vec![IDENTITY];
    // Close the set under the quarter turns about x and z, which generate the group.
    let generators = [about([1.0, 0.0, 0.0], h), about([0.0, 0.0, 1.0], h)];
    let mut i = 0;
    while i < all.len() {
        for g in &generators {
            let next = normalise(&mul(g, &all[i]));
            if all.iter().all(|q| angle_between(q, &next) > 1e-6) {
                all.push(next);
            }
        }
        i += 1;
    }
    all.try_into().expect("a cube has 24 rotations")
}

/// The 24 proper rotations of a cube, computed once.
pub fn cube_group() -> &'static [Quat; 24] {
    static GROUP: std::sync::OnceLock<[Quat; 24]> = std::sync::OnceLock::new();
    GROUP.get_or_init(cube_rotations)
}

/// The cube rotation nearest to `q`, and the angle between them. The nearest rotation has
/// the largest |⟨g, q⟩|, so only that one needs an arccos; this runs in every physics substep
/// of the physical cube, seven times.
pub fn snap_to_cube(q: &Quat, rotations: &[Quat; 24]) -> (Quat, f64) {
    let dot = |g: &Quat| g.iter().zip(q).map(|(a, b)| a * b).sum::<f64>().abs();
    let (mut best, mut best_dot) = (rotations[0], dot(&rotations[0]));
    for g in &rotations[1..] {
        let d = dot(g);
        if d > best_dot {
            (best, best_dot) = (*g, d);
        }
    }
    (best, 2.0 * best_dot.min(1.0).acos())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn twenty_four_distinct_rotations_mapping_axes_to_axes() {
        let all = cube_rotations();
        for q in &all {
            let x = rotate(q, [1.0, 0.0, 0.0]);
            assert!(x.iter().filter(|c| c.abs() > 0.999).count() == 1, "{x:?}");
        }
        let (snapped, error) = snap_to_cube(&about([0.0, 0.0, 1.0], 1.65), &all);
        assert!((error - (1.65 - std::f64::consts::FRAC_PI_2)).abs() < 1e-9);
        assert!(
            (twist_about(&snapped, [0.0, 0.0, 1.0]) - std::f64::consts::FRAC_PI_2).abs() < 1e-9
        );
    }
}
