//! The safe Rust API on a device of the plugin's own: calls reach the C functions, failures come back as
//! errors carrying the code and the plugin's message, and dropping the context destroys it.

use hrts::glam::{Mat4, Vec3};
use hrts::{Config, Context, CpuGeometry, Draw, HeadlessOptions, HrtsResult, Resource, ShadowMode};

#[test]
fn a_headless_context_configures_takes_geometry_and_reports_errors() {
    let before = hrts::memory_stats().expect("memory stats");
    assert_eq!(
        before.host_bytes, None,
        "the rlib keeps the program's allocator"
    );
    let context = Context::headless(&HeadlessOptions::default()).expect("headless context");
    let caps = context.capabilities().expect("capabilities");
    assert!(!caps.device_name.is_empty() && caps.max_map_size >= 1024);

    let too_big = caps.max_map_size.min(u32::from(u16::MAX)) + 1;
    let error = context
        .configure(&Config {
            map_size: too_big,
            ..Config::default()
        })
        .expect_err("a map larger than the device's images is refused");
    assert_eq!(error.call(), "hrts_configure");
    assert_eq!(error.code(), HrtsResult::ErrorInvalidArgument);
    assert!(
        error
            .message()
            .contains(&format!("primitive map size {too_big}")),
        "{error}"
    );
    assert!(
        error
            .to_string()
            .starts_with("hrts_configure: HRTS_RESULT_ERROR_INVALID_ARGUMENT ("),
        "{error}"
    );

    let hard = Config {
        mode: ShadowMode::Hard,
        antialiasing: false,
        ..Config::default()
    };
    context
        .configure_lights(&[hard, Config::default()])
        .expect("two lights");
    let positions = [Vec3::ZERO, Vec3::X, Vec3::Z, Vec3::new(1.0, 0.0, 1.0)];
    let draw = Draw {
        first_index: 0,
        index_count: 6,
        transform: Mat4::from_translation(Vec3::Y),
        base_vertex: 0,
    };
    context
        .set_geometry_cpu(&CpuGeometry {
            positions: &positions,
            indices: &[0, 1, 2, 2, 1, 3],
            draws: &[draw],
        })
        .expect("CPU geometry");
    context
        .set_draw_transforms(&[Mat4::IDENTITY])
        .expect("one transform per draw");
    let error = context
        .set_draw_transforms(&[Mat4::IDENTITY; 2])
        .expect_err("two transforms for one draw");
    assert_eq!(error.code(), HrtsResult::ErrorInvalidArgument, "{error}");

    // Without targets nothing is built yet, and no frame was recorded.
    let error = context
        .resource_info(0, Resource::RtVisibility)
        .expect_err("no targets");
    assert_eq!(error.code(), HrtsResult::ErrorInvalidState, "{error}");
    let error = context.frame_report(0, 0).expect_err("no frame recorded");
    assert!(!error.message().is_empty(), "{error}");

    drop(context);
    let after = hrts::memory_stats().expect("memory stats");
    assert_eq!(
        after.gpu_bytes, before.gpu_bytes,
        "dropping the context frees its GPU memory"
    );
}
