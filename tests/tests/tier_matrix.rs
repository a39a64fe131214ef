//! The binning matrix on this device: every binning path it offers (compute and the software
//! geometry-shader raster everywhere; with `VK_EXT_conservative_rasterization` also the native tier and a
//! Tier-1 emulation) stores the exact conservative set in every texel. The paths run are printed and must
//! be exactly those the device's capabilities allow.

mod common;

use common::*;
use hrts_lab::tiers::{available_requests, markdown, standard_scenes, tier_matrix};
use passes::BinningRequest;

#[test]
fn every_available_binning_path_stores_the_exact_conservative_set() {
    let device = device();
    let requests = available_requests(&device);
    assert!(
        requests.contains(&BinningRequest::Compute),
        "compute binning runs everywhere"
    );
    let caps = device.capabilities();
    assert_eq!(
        requests.contains(&BinningRequest::Software),
        caps.geometry_shader
    );
    let hw = caps.hardware_conservative_raster();
    assert_eq!(requests.contains(&BinningRequest::Hardware), hw);
    assert_eq!(
        requests.contains(&BinningRequest::EmulateTier1),
        hw && caps.geometry_shader
    );
    let rows = tier_matrix(
        &device,
        &standard_scenes(&models()).expect("scenes load"),
        256,
    )
    .expect("matrix runs");
    println!("{}", markdown(&device, &rows));
    assert_eq!(rows.len(), 2 * requests.len());
    for r in &rows {
        assert!(r.passed(), "{} on {}: {:?}", r.path, r.scene, r.map);
        assert_eq!(r.map.past_capacity, 0, "{} on {}", r.path, r.scene);
        assert_eq!(r.map.texels, 256 * 256);
    }
    assert_no_validation_errors(&device);
}
