//! Compiles the engine's GLSL shaders in `shaders/` (the G-buffer) to SPIR-V and embeds the modules (see
//! `shader_build`). Includes resolve in `shaders/`: the engine's shaders read its own buffers alone.

fn main() {
    let manifest = std::path::PathBuf::from(
        std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"),
    );
    shader_build::embed_shaders(&manifest.join("shaders"), &[]);
}
