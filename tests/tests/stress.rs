//! The numerical stress suite's short run (`rt_validate::stress`, `Budget::ci`); `render stress
//! --long` runs the same cases with a larger budget. One test per group, so the groups run in
//! parallel and a failure names its group; each prints its cases' report lines.

use rt_validate::stress::{cases_named, Budget};

fn run_group(prefix: &str) {
    run_group_at(prefix, 1);
}

fn run_group_at(prefix: &str, seed: u64) {
    // The shared meshes are found in `rt_validate::data::default_dir()`; under
    // RT_REQUIRE_DATA=1 a missing one fails its case.
    let budget = Budget::ci();
    let cases = cases_named(prefix);
    assert!(!cases.is_empty(), "no case named {prefix}*");
    let reports: Vec<_> = cases.iter().map(|c| c.run(&budget, seed)).collect();
    let lines: Vec<String> = reports.iter().map(|r| r.to_string()).collect();
    println!("{}", lines.join("\n"));
    let failed: Vec<&String> = reports
        .iter()
        .zip(&lines)
        .filter(|(r, _)| !r.passed())
        .map(|(_, l)| l)
        .collect();
    assert!(
        failed.is_empty(),
        "failed:\n{}",
        failed
            .iter()
            .map(|l| l.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    );
}

#[test]
fn transformed_scenes_render_the_same_image() {
    run_group("transform/");
}

#[test]
fn rays_never_hit_the_surface_they_leave() {
    run_group("self-hit/");
}

#[test]
fn bad_geometry_gives_finite_images_and_discards_nothing() {
    run_group("bad/");
}

/// The seed at which a bounce ray starting in a corner of the closed box left it through the
/// adjacent wall (that hit lay within the single-precision error bound of its `t`, and PBRT's
/// rule drops such hits: `rt_core::triangle::intersect_triangle` now decides them in double
/// precision).
#[test]
fn the_closed_box_leaks_nothing_where_a_corner_ray_once_escaped() {
    run_group_at("bad/closed-box-no-leaks", 5);
}
