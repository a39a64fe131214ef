//! The SPIR-V of the passes' shaders, compiled from `shaders/` at build time by `glslang` (build.rs) and
//! embedded in the library.

use crate::PassError;
use rhi::Format;

mod compiled {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}

/// SPIR-V words of the embedded shader `name` (file name in `shaders/`).
pub fn shader(name: &str) -> Result<Vec<u32>, PassError> {
    compiled::spirv(name)
        .ok_or_else(|| PassError::InvalidConfig(format!("no embedded shader named {name}")))
}

/// The name of the module of shader `name` that writes its final visibility into an image of `format`:
/// `name` itself for `R32_SFLOAT`, its `r16f` or `r8` variant (`shader_build`'s `OUTPUT_FORMAT`) for an
/// engine's `R16_SFLOAT` or `R8_UNORM` output layer written directly.
pub fn output_variant(name: &str, format: Format) -> Result<String, PassError> {
    match format {
        Format::R32Float => Ok(name.to_owned()),
        Format::R16Float => Ok(format!("{name}@r16f")),
        Format::R8Unorm => Ok(format!("{name}@r8")),
        other => Err(PassError::InvalidConfig(format!(
            "{name} writes its visibility into R32_SFLOAT, R16_SFLOAT or R8_UNORM images, not {other:?}"
        ))),
    }
}

/// Names of all embedded shader modules.
pub fn shader_names() -> impl Iterator<Item = &'static str> {
    compiled::ALL.iter().map(|(n, _)| *n)
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_shader_is_spirv() {
        let names: Vec<_> = super::shader_names().collect();
        assert!(names.len() >= 9, "{names:?}");
        for n in names {
            let words = super::shader(n).unwrap();
            assert_eq!(words[0], 0x0723_0203, "{n} lacks the SPIR-V magic number");
        }
    }

    #[test]
    fn every_final_pass_has_a_variant_per_output_format() {
        use rhi::Format;
        for n in [
            "ray_trace.comp",
            "area_trace.comp",
            "area_trace_local.comp",
            "area_trace_narrow.comp",
            "pcss.comp",
            "pcss_rt.comp",
            "hybrid_blend.comp",
            "fxaa.comp",
            "min_combine.comp",
        ] {
            for format in [Format::R32Float, Format::R16Float, Format::R8Unorm] {
                let variant = super::output_variant(n, format).unwrap();
                assert!(super::shader(&variant).is_ok(), "{variant} is not embedded");
            }
        }
        assert!(super::output_variant("fxaa.comp", Format::Rgba8Unorm).is_err());
        assert!(
            super::shader("scan.comp@r8").is_err(),
            "scan writes no visibility"
        );
    }
}
