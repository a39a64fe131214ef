//! The conservative-raster tier matrix on this device: every raster path it offers (on lavapipe the
//! software geometry-shader path; with `VK_EXT_conservative_rasterization` also the native tier and a
//! Tier-1 emulation) stores the exact conservative set in every texel. The paths run are printed and
//! must be exactly those the device's capabilities allow.

mod common;

use common::*;
use host_demo::tiers::{available_requests, markdown, standard_scenes, tier_matrix};
use passes::RasterRequest;

#[test]
fn every_available_raster_path_stores_the_exact_conservative_set() {
    let device = device();
    let requests = available_requests(&device);
    assert!(
        requests.contains(&RasterRequest::Software),
        "the software path must run everywhere"
    );
    let hw = device.capabilities().hardware_conservative_raster();
    assert_eq!(requests.contains(&RasterRequest::Hardware), hw);
    assert_eq!(
        requests.contains(&RasterRequest::EmulateTier1),
        hw && device.capabilities().geometry_shader
    );
    let models = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/models");
    let rows = tier_matrix(
        &device,
        &standard_scenes(&models).expect("scenes load"),
        256,
        1024,
    )
    .expect("matrix runs");
    println!("{}", markdown(&device, &rows));
    assert_eq!(rows.len(), 2 * requests.len());
    for r in &rows {
        assert!(r.passed(), "{} on {}: {:?}", r.path, r.scene, r.map);
        if !r.path.contains("tier-1") {
            // Exact paths are compared on every texel: d is chosen so that none overflows.
            assert_eq!(r.map.overflowed, 0, "{} on {}", r.path, r.scene);
        }
    }
    assert_no_validation_errors(&device);
}
