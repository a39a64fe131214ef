//! Compiles the tests' own GLSL probes in `shaders/` to SPIR-V and embeds the modules (see `shader_build`).
//! Includes resolve in `shaders/`, then in `../passes/shaders/`: a probe runs the passes' own functions.

fn main() {
    let manifest = std::path::PathBuf::from(
        std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"),
    );
    shader_build::embed_shaders(
        &manifest.join("shaders"),
        &[manifest.join("../passes/shaders")],
    );
}
