//! The SPIR-V of the passes' shaders, compiled from `shaders/` at build time by `glslang` (build.rs) and
//! embedded in the library.

use crate::PassError;

mod compiled {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}

/// SPIR-V words of the embedded shader `name` (file name in `shaders/`).
pub fn shader(name: &str) -> Result<Vec<u32>, PassError> {
    embedded_shader(compiled::ALL, name)
}

/// SPIR-V words of shader `name` in a table of embedded modules (as `shader_build` writes them).
pub fn embedded_shader(table: &[(&str, &[u8])], name: &str) -> Result<Vec<u32>, PassError> {
    let bytes = table
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, b)| *b)
        .ok_or_else(|| PassError::InvalidConfig(format!("no embedded shader named {name}")))?;
    Ok(bytemuck::pod_collect_to_vec(bytes))
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
}
