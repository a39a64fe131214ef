//! For build scripts: compiles every GLSL shader of a folder to SPIR-V with the glslang crate (Vulkan 1.3,
//! SPIR-V 1.6) and writes `$OUT_DIR/shaders.rs`, a table `ALL: &[(&str, &[u8])]` of the modules by file
//! name and `spirv(name)`, a module's words, for `include!`. A shader that does not compile fails the build with glslang's message.
//!
//! A shader whose source or includes name [`OUTPUT_FORMAT`] (the format qualifier of the image its final
//! visibility goes into, `r32f` unless defined) is also compiled once per [`OUTPUT_FORMAT_VARIANTS`] value,
//! embedded as `NAME@VALUE` (`ray_trace.comp@r16f`).

use glslang::{
    include::{IncludeHandler, IncludeResult, IncludeType},
    Compiler, CompilerOptions, ShaderInput, ShaderSource, ShaderStage, SourceLanguage,
    SpirvVersion, Target, VulkanVersion,
};
use std::path::{Path, PathBuf};

/// The macro naming the format qualifier of a shader's final output image.
pub const OUTPUT_FORMAT: &str = "OUTPUT_FORMAT";

/// The values of [`OUTPUT_FORMAT`] besides the default `r32f` that each shader naming it is compiled with.
pub const OUTPUT_FORMAT_VARIANTS: [&str; 2] = ["r16f", "r8"];

/// Include folders, searched in order, and whether an included file named [`OUTPUT_FORMAT`].
struct Includes {
    dirs: Vec<PathBuf>,
    names_output_format: bool,
}

impl IncludeHandler for Includes {
    fn include(
        &mut self,
        _ty: IncludeType,
        name: &str,
        _includer: &str,
        _depth: usize,
    ) -> Option<IncludeResult> {
        let found = self.dirs.iter().find_map(|dir| {
            let path = dir.join(name);
            let data = std::fs::read_to_string(&path).ok()?;
            println!("cargo:rerun-if-changed={}", path.display());
            Some(IncludeResult {
                name: path.to_string_lossy().into_owned(),
                data,
            })
        });
        if found
            .as_ref()
            .is_some_and(|f| f.data.contains(OUTPUT_FORMAT))
        {
            self.names_output_format = true;
        }
        found
    }
}

fn stage_of(path: &Path) -> ShaderStage {
    match path.extension().and_then(|e| e.to_str()) {
        Some("vert") => ShaderStage::Vertex,
        Some("geom") => ShaderStage::Geometry,
        Some("frag") => ShaderStage::Fragment,
        Some("comp") => ShaderStage::Compute,
        Some("rgen") => ShaderStage::RayGeneration,
        Some("rmiss") => ShaderStage::Miss,
        other => panic!("unknown shader stage {other:?} for {}", path.display()),
    }
}

/// Compiles every shader in `dir` (`.glsl` files are includes only), resolving includes in `dir` and then
/// in `include_dirs`, and writes the SPIR-V modules and `shaders.rs` into `$OUT_DIR`.
pub fn embed_shaders(dir: &Path, include_dirs: &[PathBuf]) {
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    println!("cargo:rerun-if-changed={}", dir.display());
    let compiler = Compiler::acquire().expect("glslang initialises");
    let options = CompilerOptions {
        source_language: SourceLanguage::GLSL,
        target: Target::Vulkan {
            version: VulkanVersion::Vulkan1_3,
            spirv_version: SpirvVersion::SPIRV1_6,
        },
        version_profile: None,
        messages: glslang::ShaderMessage::DEFAULT,
    };
    let search: Vec<PathBuf> = std::iter::once(dir.to_path_buf())
        .chain(include_dirs.iter().cloned())
        .collect();
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.extension().is_some_and(|e| e != "glsl"))
        .collect();
    entries.sort();
    let mut table = String::from(
        "/// Every embedded shader module, by file name.\npub const ALL: &[(&str, &[u8])] = &[\n",
    );
    for path in entries {
        println!("cargo:rerun-if-changed={}", path.display());
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .expect("utf-8 shader name")
            .to_owned();
        let text = std::fs::read_to_string(&path).expect("readable shader");
        let mut includes = Includes {
            dirs: search.clone(),
            names_output_format: false,
        };
        let words = compile(compiler, &options, &path, &text, &mut includes, None);
        let mut modules = vec![(name.clone(), words)];
        if includes.names_output_format || text.contains(OUTPUT_FORMAT) {
            for value in OUTPUT_FORMAT_VARIANTS {
                let define = Some((OUTPUT_FORMAT, value));
                let words = compile(compiler, &options, &path, &text, &mut includes, define);
                modules.push((format!("{name}@{value}"), words));
            }
        }
        for (name, words) in modules {
            let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
            let file = format!("{name}.spv");
            std::fs::write(out.join(&file), bytes).expect("write SPIR-V");
            table.push_str(&format!(
                "    (\"{name}\", include_bytes!(concat!(env!(\"OUT_DIR\"), \"/{file}\"))),\n"
            ));
        }
    }
    table.push_str(concat!(
        "];\n\n",
        "/// The SPIR-V words of the embedded module `name` (a file name), if there is one.\n",
        "pub fn spirv(name: &str) -> Option<Vec<u32>> {\n",
        "    let (_, bytes) = ALL.iter().find(|(n, _)| *n == name)?;\n",
        "    Some(\n",
        "        bytes\n",
        "            .chunks_exact(4)\n",
        "            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))\n",
        "            .collect(),\n",
        "    )\n",
        "}\n",
    ));
    std::fs::write(out.join("shaders.rs"), table).expect("write shader table");
}

/// The SPIR-V of the shader at `path` (source `text`), with the macro `define` set if given.
fn compile(
    compiler: &Compiler,
    options: &CompilerOptions,
    path: &Path,
    text: &str,
    includes: &mut Includes,
    define: Option<(&str, &str)>,
) -> Vec<u32> {
    let name = path.display();
    let source = ShaderSource::from(text.to_owned());
    let defines: Vec<(&str, Option<&str>)> =
        define.map(|(k, v)| (k, Some(v))).into_iter().collect();
    let input = ShaderInput::new(
        &source,
        stage_of(path),
        options,
        Some(defines.as_slice()),
        Some(includes),
    )
    .unwrap_or_else(|e| panic!("{name}: {e}"));
    let shader = compiler
        .create_shader(input)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    shader.compile().unwrap_or_else(|e| panic!("{name}: {e}"))
}
