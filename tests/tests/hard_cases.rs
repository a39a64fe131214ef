//! The hard numerical cases of `scene::hard_cases`, one test per family, run through
//! `hrts_lab::hardcases::run_cases` — the code behind `hrts_lab hardcases` — so that the table and the
//! tests cannot drift apart.
//!
//! Every rendered case must have, with Vulkan validation on:
//! - no visibility mismatch with the exact reference outside the counted near-edge pixels (and no
//!   blocker-distance mismatch where blocker distances are comparable: both faces stored);
//! - no leak (a lit receiver whose shadow ray passes through a blocker shrunk by two pixel footprints) and
//!   no acne (a shadowed light-facing receiver with nothing towards the light), each analytic check
//!   judging at least one pixel;
//! - no NaN/Inf, no missing or garbage primitive-map entry, the guard layer untouched, no validation error;
//! - contact shadows starting less than one pixel from the contact; translated copies of the demo scene
//!   differing from the original on at most 14, 42 and 140 pixels (1e3, 1e4, 1e5: 0.05%, 0.15%, 0.5% of
//!   the frame, from the f32 rounding of the translated input) and scaled copies on none.
//!
//! NaN/Inf input must be rejected at load time with an error naming the non-finite coordinate.

mod common;

use common::{assert_no_validation_errors, device, models};
use demo_engine::gbuffer::GBufferLayout;
use hrts_lab::hardcases::{run_cases, table, Outcome};
use rhi::Device;
use scene::hard_cases::{family, Expectation, Family};

/// Runs the light cases of `f` on a validated device, prints their table and checks each.
fn check_family(f: Family) -> Vec<Outcome> {
    check_family_with(&device(), f, GBufferLayout::ANALYSIS)
}

/// [`check_family`] on `device` with the plugin reading a G-buffer of `layout`.
fn check_family_with(device: &Device, f: Family, layout: GBufferLayout) -> Vec<Outcome> {
    let cases: Vec<_> = family(f, &models()).into_iter().collect();
    assert!(!cases.is_empty());
    let outcomes = run_cases(device, &cases, layout, None);
    println!("{}", table(&outcomes, false));
    for (case, o) in cases.iter().zip(&outcomes) {
        match case.expectation {
            Expectation::RejectedAtLoad => {
                let message = o.rejected.as_deref().unwrap_or_else(|| {
                    panic!("{}: NaN/Inf input was not rejected: {:?}", o.name, o.error)
                });
                assert!(message.contains("non-finite"), "{}: {message}", o.name);
            }
            Expectation::Renders(_) => assert_rendered(o),
        }
    }
    assert_no_validation_errors(device);
    outcomes
}

fn assert_rendered(o: &Outcome) {
    let name = o.name;
    assert_eq!(o.error, None, "{name}");
    assert!(o.pixels > 0, "{name}: nothing rendered");
    assert_eq!(
        o.mismatches, 0,
        "{name}: visibility mismatches outside the {} near-edge pixels, e.g. (x, y, exact, GPU) {:?}",
        o.near_edge, o.examples
    );
    if o.blocker_distance_compared {
        assert_eq!(
            o.blocker_mismatches, 0,
            "{name}: blocker-distance mismatches, e.g. (x, y, what, GPU - exact) {:?}",
            o.examples
        );
    }
    assert_eq!(o.leaks, 0, "{name}: leaks");
    assert_eq!(o.acne, 0, "{name}: acne");
    assert!(
        o.vacuous_checks.is_empty(),
        "{name}: checks that judged no pixel: {:?}",
        o.vacuous_checks
    );
    assert_eq!(o.non_finite, 0, "{name}: NaN/Inf pixels");
    assert_eq!(o.map_missing, 0, "{name}: missing primitive-map entries");
    assert_eq!(o.map_garbage, 0, "{name}: garbage primitive-map entries");
    assert_eq!(
        o.guard_written.unwrap_or(0),
        0,
        "{name}: guard layer written"
    );
    assert_eq!(o.validation_errors, 0, "{name}: validation errors");
    if let Some(gap) = o.contact_gap_pixels {
        assert!(gap < 1.0, "{name}: contact shadow starts {gap:.2} px away");
    }
    if let Some(d) = o.differing_pixels {
        assert!(
            d.total <= d.bound,
            "{name}: {} pixels differ from the untransformed scene (bound {})",
            d.total,
            d.bound
        );
    }
    assert!(o.passed(), "{name}: {}", o.result());
}

#[test]
fn shadow_rays_through_shared_edges_and_vertices_do_not_leak() {
    let outcomes = check_family(Family::SharedEdges);
    for o in &outcomes {
        assert!(o.judged[0] > 1000, "{}: too few receivers judged", o.name);
    }
}

#[test]
fn grazing_light_causes_no_acne() {
    let outcomes = check_family(Family::Grazing);
    for o in &outcomes {
        assert!(o.judged[1] > 1000, "{}: too few receivers judged", o.name);
    }
}

#[test]
fn contact_shadows_start_at_the_contact() {
    for o in check_family(Family::Contact) {
        assert!(o.judged[2] > 1000, "{}: too few receivers judged", o.name);
        assert!(o.contact_gap_pixels.is_some_and(|g| g < 1.0), "{}", o.name);
    }
}

#[test]
fn translated_and_scaled_scenes_match_the_original() {
    let outcomes = check_family(Family::Scale);
    assert_eq!(outcomes.len(), 6);
    for o in &outcomes[1..] {
        assert!(o.differing_pixels.is_some(), "{}", o.name);
    }
}

#[test]
fn sub_texel_needle_and_zero_area_triangles() {
    check_family(Family::SmallTriangles);
}

#[test]
fn triangles_on_texel_boundaries() {
    check_family(Family::TexelBoundaries);
}

#[test]
fn triangles_crossing_the_light_map_border_and_depth_range() {
    check_family(Family::FrustumBorder);
}

#[test]
fn coplanar_overlapping_faces() {
    check_family(Family::Coplanar);
}

#[test]
fn thin_plates_and_foliage_cards() {
    check_family(Family::ThinGeometry);
}

#[test]
fn real_models() {
    check_family(Family::Models);
}

#[test]
fn non_finite_input_is_rejected_at_load() {
    let outcomes = check_family(Family::NonFinite);
    assert!(outcomes.iter().all(|o| o.rejected.is_some()));
}

#[test]
fn overflow_keeps_the_guard_layer_and_exact_visibility() {
    for o in check_family(Family::Overflow) {
        assert!(
            o.texels_past_capacity > 0,
            "{}: no texel past the entry capacity",
            o.name
        );
        assert_eq!(o.guard_written, Some(0), "{}", o.name);
    }
}

/// The families where the engine's normal decides most (which side of a grazing light a receiver faces,
/// where a ray leaves a surface touching another), with the plugin reading each normal target engines keep
/// instead of RGBA32F: quantized and octahedral normals, in world and view space. (The whole suite for every
/// encoding: `hrts_lab hardcases --normals NAME`, docs/hardcases_normal_encodings_lavapipe.txt.)
#[test]
fn grazing_and_contact_cases_hold_with_every_normal_encoding() {
    let device = device();
    for (name, ..) in demo_engine::gbuffer::NORMAL_TARGETS.iter().skip(1) {
        let layout = GBufferLayout::analysis_with(name).expect("a named normal target");
        for f in [Family::Grazing, Family::Contact, Family::Coplanar] {
            println!("normals {name}, {}", f.name());
            check_family_with(&device, f, layout);
        }
    }
}
