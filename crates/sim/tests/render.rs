//! Offscreen rendering on a headless machine: the picture shows the cube as it is.

use dexcube_sim::render::{DEFAULT_CAMERA, FrameRenderer, save_png};
use dexcube_sim::{Scene, SceneKind, Sim};

/// Share of pixels in a region whose colour is near `rgb`.
fn share_near(
    frame: &dexcube_sim::render::Frame,
    rows: std::ops::Range<usize>,
    rgb: [u8; 3],
) -> f64 {
    let mut hits = 0;
    let mut total = 0;
    for y in rows {
        for x in frame.width / 3..2 * frame.width / 3 {
            let p = &frame.rgb[(y * frame.width + x) * 3..][..3];
            let distance: i32 = p
                .iter()
                .zip(rgb)
                .map(|(&a, b)| (a as i32 - b as i32).abs())
                .sum();
            hits += (distance < 120) as usize;
            total += 1;
        }
    }
    hits as f64 / total as f64
}

#[test]
fn the_rigid_cube_shows_its_front_face_below_its_top_face() {
    let mut sim = Sim::new(Scene::load(SceneKind::Rot).unwrap());
    let mut renderer = FrameRenderer::new(&sim, 320, 240, DEFAULT_CAMERA).unwrap();
    let frame = renderer.render(&mut sim).unwrap();
    assert_eq!(frame.rgb.len(), 320 * 240 * 3);
    // The camera looks at F (green) from the front and above: green in the middle band,
    // with U (white) just above it, right side up.
    let green = share_near(&frame, 120..160, [13, 110, 30]);
    let white_above = share_near(&frame, 100..118, [255, 255, 255]);
    let green_above = share_near(&frame, 100..118, [13, 110, 30]);
    assert!(
        green > 0.3,
        "the green front face fills the middle: {green}"
    );
    assert!(
        white_above > green_above,
        "white top face above the front face"
    );
    let path = std::env::temp_dir().join("dexcube-render-test.png");
    save_png(&frame, &path).unwrap();
    assert!(std::fs::metadata(&path).unwrap().len() > 1000);
}

#[test]
fn a_missing_camera_is_named() {
    let sim = Sim::new(Scene::load(SceneKind::Cube).unwrap());
    let err = FrameRenderer::new(&sim, 64, 48, "nowhere").err().unwrap();
    assert!(err.to_string().contains("camera named 'nowhere'"), "{err}");
}
