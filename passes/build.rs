//! Compiles every GLSL shader in `shaders/` to SPIR-V and embeds the modules (see `shader_build`).

fn main() {
    let manifest = std::path::PathBuf::from(
        std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"),
    );
    shader_build::embed_shaders(&manifest.join("shaders"), &[]);
}
