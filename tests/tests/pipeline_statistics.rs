//! What the driver says each pipeline costs (`rhi::DeviceDesc::pipeline_statistics`,
//! `VK_KHR_pipeline_executable_properties`): where the device offers the extension (NVIDIA's driver does;
//! Mesa 25.0's lavapipe does not), every trace pipeline of a frame reports its statistics; where it does
//! not, or where nobody asked, none is captured and the frame is the same.

mod common;

use common::{assert_no_validation_errors, plate_and_box_view, ViewInputs};
use passes::{PcssConfig, ShadowConfig, ShadowMode};
use rhi::{Device, DeviceDesc, StatisticsUnavailable};
use test_support::ShadowRenderer;

/// A device with validation, capturing the pipelines' statistics if `capture`.
fn device_capturing(capture: bool) -> Device {
    let desc = DeviceDesc {
        validation: true,
        pipeline_statistics: capture,
        ..DeviceDesc::from_env()
    };
    Device::new_headless(&desc).expect("device")
}

/// Renders one frame of area shadows of a sun (the trace and its variants, the map's passes).
fn render_area_frame(device: &Device) {
    let view = plate_and_box_view(64, 48);
    let config = ShadowConfig {
        mode: ShadowMode::Area,
        pcss: PcssConfig {
            angular_radius: 0.05,
            ..PcssConfig::default()
        },
        ..ShadowConfig::default()
    };
    let mut r = ShadowRenderer::new(device, &view, config).expect("renderer");
    r.render(device, &view.frame_inputs()).expect("render");
}

/// Asked for, the statistics are none where the device does not offer the extension, and otherwise hold
/// every trace pipeline of the frame with the values the driver gives; either way the frame renders and
/// validation stays silent.
#[test]
fn pipelines_report_what_they_cost_where_the_device_offers_it() {
    let device = device_capturing(true);
    render_area_frame(&device);
    assert_no_validation_errors(&device);
    let name = &device.capabilities().device_name;
    let statistics = match device.pipeline_statistics() {
        Ok(statistics) => statistics,
        Err(why) => {
            assert_eq!(why, StatisticsUnavailable::NotOffered, "asked, yet {why:?}");
            println!("pipeline statistics on {name}: none (VK_KHR_pipeline_executable_properties not offered)");
            return;
        }
    };
    println!("pipeline statistics on {name}:");
    for s in &statistics {
        println!("{} [{}]: {:?}", s.pipeline, s.executable, s.values);
    }
    for name in [
        "area trace (directional lights, never wide)",
        "area trace (directional lights)",
        "area trace (spot and point lights)",
        "bvh build",
    ] {
        let found: Vec<_> = statistics.iter().filter(|s| s.pipeline == name).collect();
        assert!(!found.is_empty(), "no statistics for {name}");
        assert!(
            found.iter().all(|s| !s.values.is_empty()),
            "{name} reports no value: {found:?}"
        );
    }
}

#[test]
fn a_device_not_asked_captures_nothing() {
    let device = device_capturing(false);
    render_area_frame(&device);
    assert_eq!(
        device.pipeline_statistics().map(|s| s.len()),
        Err(StatisticsUnavailable::NotAsked)
    );
    assert_no_validation_errors(&device);
}
