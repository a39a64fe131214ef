//! The **non-finite** family: NaN/Inf input, which must be rejected at load time.

use std::path::Path;

use super::{ground, solid_box, with, Expectation, Family, HardCase, MapSpec, FRAME};
use crate::obj::parse_obj;
use crate::DirectionalLight;

/// The cases of the `non-finite` family, in table order.
pub(super) fn non_finite() -> Vec<HardCase> {
    let rejected = |name: &'static str, description: &'static str, scene| HardCase {
        name,
        family: Family::NonFinite,
        description,
        scene,
        light_direction: DirectionalLight::slanted().direction,
        camera: None,
        light_view_proj: None,
        frame: FRAME,
        map: MapSpec::new(64),
        expectation: Expectation::RejectedAtLoad,
    };
    let obj = |file: &str, text: &str| parse_obj(text.as_bytes(), Path::new(file));
    let mut in_memory = with(ground(4.0), [solid_box("box", [0.0; 3], [1.0; 3])]);
    in_memory.positions[5].z = f32::NAN;
    vec![
        rejected(
            "NaN vertex (OBJ)",
            "`v nan 1 0` in an OBJ file.",
            obj("nan.obj", "v 0 0 0\nv nan 1 0\nv 0 0 1\nf 1 2 3\n"),
        ),
        rejected(
            "infinite vertex (OBJ)",
            "`v 1 inf 0` and `v -inf 0 0` in an OBJ file.",
            obj("inf.obj", "v 0 0 0\nv 1 inf 0\nv -inf 0 1\nf 1 2 3\n"),
        ),
        rejected(
            "overflowing vertex 1e39 (OBJ)",
            "`v 0 0 1e39`: finite text that overflows f32 to infinity.",
            obj("overflow.obj", "v 0 0 0\nv 1 0 0\nv 0 0 1e39\nf 1 2 3\n"),
        ),
        rejected(
            "NaN in an in-memory scene",
            "A scene built in memory with a NaN coordinate, checked by `Scene::validate`.",
            in_memory.validate().map(|()| in_memory.clone()),
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_errors_name_the_problem() {
        for c in non_finite() {
            let e = c.scene.unwrap_err().to_string();
            assert!(e.contains("non-finite"), "{e}");
        }
    }
}
