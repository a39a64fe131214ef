//! `hrts_lab tradeoff` on a contact-hardening scene (a plate high above the ground and a box standing on
//! it), on lavapipe: the numbers are checked, never the timings. The ground-truth soft shadow converges;
//! soft shadows beat hard ones against it; the hybrid beats the hard shadow it starts from; more PCSS taps
//! and the standard penumbra move PCSS towards the truth; area shadows at 64 samples beat every other
//! family, and more samples move them towards the truth; the outputs (CSV, JSON, the Pareto plot, the
//! error maps) are written and consistent with the table.

mod common;

use common::*;
use hrts_lab::tradeoff::{run_sweep, TradeoffArgs};
use reference::{reference_visibility, soft_visibility, AreaLight, RefScene, SoftParams};

fn args(out: std::path::PathBuf, strata: u32) -> TradeoffArgs {
    TradeoffArgs {
        obj: None,
        builtin: false,
        width: 128,
        height: 96,
        frames: 2,
        strata,
        angular_radius: 0.05,
        out,
    }
}

#[test]
fn the_ground_truth_converges() {
    let view = plate_and_box_view(96, 72);
    let rs = RefScene::new(&view.scene);
    let params = visibility_params(&view);
    let hard = reference_visibility(&rs, &params);
    let light = AreaLight::Directional {
        direction: view.frame_inputs().light.direction().as_dvec3(),
        angular_radius: 0.05,
    };
    let estimate = |strata| {
        soft_visibility(
            &rs,
            &hard,
            &light,
            &SoftParams {
                strata,
                seed: 7,
                camera_position: params.camera_position,
            },
        )
        .expect("ground truth")
    };
    let (coarse, medium, fine) = (estimate(4), estimate(8), estimate(32));
    assert!(fine.sampled_pixels > 100, "the view has a penumbra");
    let mean_difference = |a: &[f64], b: &[f64]| {
        let d: Vec<f64> = a
            .iter()
            .zip(b)
            .filter(|(x, _)| !x.is_nan())
            .map(|(x, y)| (x - y).abs())
            .collect();
        d.iter().sum::<f64>() / d.len() as f64
    };
    let coarse_error = mean_difference(&coarse.visibility, &fine.visibility);
    let medium_error = mean_difference(&medium.visibility, &fine.visibility);
    println!("mean |estimate − 1024-sample estimate|: 16 samples {coarse_error:.5}, 64 samples {medium_error:.5}");
    assert!(
        medium_error < coarse_error,
        "more samples move the estimate closer to the converged one ({medium_error} ≥ {coarse_error})"
    );
    assert!(fine.standard_error_bound <= 0.5 / 32.0 + 1e-12);
    // Pixels decided exactly are the same at every sample count.
    assert_eq!(coarse.exact_pixels, fine.exact_pixels);
}

#[test]
fn soft_shadows_approach_the_truth_and_the_outputs_are_written() {
    let device = device();
    let view = plate_and_box_view(128, 96);
    let dir = std::env::temp_dir().join(format!("hrts-tradeoff-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let sweep = run_sweep(&device, &view, "plate and box", &args(dir.clone(), 16)).expect("sweep");
    println!("{}", sweep.table());
    let error = |name: &str| {
        sweep
            .rows()
            .iter()
            .find(|r| format!("{} {}", r.family, r.method) == name)
            .unwrap_or_else(|| panic!("no row {name}"))
            .mean_abs_error
    };
    let best = |family| sweep.best(family).expect(family).mean_abs_error;
    // Soft shadows matter: the best PCSS is closer to the truth than any hard shadow.
    for hard in ["shadow map", "ray traced"] {
        assert!(
            best("PCSS") < best(hard),
            "PCSS {} ≥ {hard} {}",
            best("PCSS"),
            best(hard)
        );
    }
    // The hybrid brings its ray-traced, antialiased hard shadow closer to the truth.
    let traced = error("ray traced hard, 1024² map, FXAA");
    assert!(
        best("hybrid") < traced,
        "hybrid {} ≥ its hard input {traced}",
        best("hybrid")
    );
    // More PCSS taps never move it away from the truth (beyond the truth's own noise).
    let noise = sweep.standard_error_bound / 4.0;
    let taps = [
        error("PCSS 3072², standard, 8+16 taps"),
        error("PCSS 3072², standard, 16+32 taps"),
        error("PCSS 3072², standard, 32+64 taps"),
    ];
    assert!(
        taps[1] <= taps[0] + noise && taps[2] <= taps[1] + noise,
        "{taps:?}"
    );
    // The standard penumbra, which straddles the hard edge as a physical one does, beats the shrinking
    // one, which grows inwards only.
    assert!(error("PCSS 3072², standard, 16+32 taps") < error("PCSS 3072², shrinking, 16+32 taps"));
    // Area shadows: exact soft shadows at 64 samples are closer to the truth than every other family's
    // best, and more samples never move them away from it (beyond the truth's own noise).
    let area = [16, 32, 64, 128].map(|n| error(&format!("area {n} samples, 1024² map")));
    for family in ["shadow map", "PCF", "PCSS", "ray traced", "hybrid"] {
        assert!(
            area[2] < best(family),
            "area 64 samples {} ≥ best {family} {}",
            area[2],
            best(family)
        );
    }
    assert!(
        area.windows(2).all(|w| w[1] <= w[0] + noise) && area[3] < area[0],
        "area errors by 16, 32, 64, 128 samples: {area:?}"
    );
    for row in sweep.rows() {
        assert!(
            row.mean_abs_error.is_finite()
                && row.mean_abs_error >= 0.0
                && (0.0..=1.0).contains(&row.p99_abs_error),
            "{row:?}"
        );
        assert!((0.0..=1.0).contains(&row.flip), "{row:?}");
        assert!(row.memory_bytes > 0, "{row:?}");
    }
    assert!(sweep.rows().iter().any(|r| r.pareto));
    sweep.write(&dir).expect("write");
    let csv = std::fs::read_to_string(dir.join("tradeoff.csv")).expect("csv");
    assert_eq!(csv.lines().count(), sweep.rows().len() + 1, "{csv}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("tradeoff.json")).expect("json"))
            .expect("valid JSON");
    assert_eq!(
        json["rows"].as_array().map(Vec::len),
        Some(sweep.rows().len())
    );
    let svg = std::fs::read_to_string(dir.join("pareto.svg")).expect("svg");
    assert!(svg.contains("<svg") && svg.contains("Pareto front"));
    assert!(dir.join("error_maps.png").is_file());
    let _ = std::fs::remove_dir_all(&dir);
    assert_no_validation_errors(&device);
}
