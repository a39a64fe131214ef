//! The C ABI as an engine uses it: a plain C program (tests/c_host: c_host.c, which runs the checks in order,
//! the files of the checks by topic, and the engine it shares with the other C tests, engine.c), built here
//! with the system compiler against the generated header and the plugin's shared library, creates its own
//! Vulkan device, fills depth and normal images itself, records the plugin into its command buffer and
//! checks the visibility against the exact shadow, then runs the misuse cases and 100 create/destroy cycles.

mod native;

use native::{compile_c, compiler, library_dir, run, workspace};
use std::path::{Path, PathBuf};
use std::process::Command;

#[test]
fn header_compiles_as_c99_and_cxx() {
    let include = workspace().join("hrts/include");
    let dir = std::env::temp_dir().join(format!("hrts-header-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let src = dir.join("use_header.c");
    std::fs::write(&src, "#include \"hrts.h\"\nint main(void) { return hrts_get_api_version() == HRTS_API_VERSION ? 0 : 1; }\n").unwrap();
    let flags = ["-Wall", "-Wextra", "-Werror", "-pedantic", "-fsyntax-only"];
    run(Command::new(compiler("cc"))
        .args(["-std=c99"])
        .args(flags)
        .arg("-I")
        .arg(&include)
        .arg(&src));
    run(Command::new(compiler("c++"))
        .args(["-std=c++17", "-x", "c++"])
        .args(flags)
        .arg("-I")
        .arg(&include)
        .arg(&src));
}

/// Builds the C program of `sources` (in tests/c_host) against the `hrts.h` in `include` and the plugin's
/// shared library; returns the executable.
fn build_c_program(name: &str, include: &Path, sources: &[&str]) -> PathBuf {
    let root = workspace();
    let lib = library_dir();
    let exe = std::env::temp_dir().join(format!("hrts-{name}-{}", std::process::id()));
    let sources: Vec<_> = sources
        .iter()
        .map(|s| root.join("tests/c_host").join(s))
        .collect();
    compile_c(&exe, include, &sources, &lib);
    exe
}

/// The C host's sources (in tests/c_host): main() and the order of the checks, the checks by topic (declared
/// in c_host.h), and the engine.
const C_HOST_SOURCES: &[&str] = &[
    "c_host.c",
    "one_light.c",
    "misuse.c",
    "lights.c",
    "frames.c",
    "geometry.c",
    "meshes.c",
    "deforming.c",
    "engine_images.c",
    "memory.c",
    "engine.c",
];

#[test]
fn c_host_matches_the_exact_shadow_and_survives_misuse() {
    let include = workspace().join("hrts/include");
    let exe = build_c_program("c-host", &include, C_HOST_SOURCES);
    let out = run(&mut Command::new(&exe));
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    assert!(stdout.contains(" 0 failed"), "{stdout}");
    assert!(stdout.contains(", 0 mismatches"), "{stdout}");
}

/// Callers built against older headers (tests/c_host/headers/<version>/hrts.h, as published: 5.1, the
/// oldest this library reads, and 5.7, the last before the element strides) get the exact shadow from the
/// current library, which writes nothing past their structs (old_caller.c).
#[test]
fn callers_of_older_headers_get_the_exact_shadow() {
    for version in ["5.1", "5.7"] {
        let include = workspace().join("tests/c_host/headers").join(version);
        let exe = build_c_program(
            &format!("old-caller-{version}"),
            &include,
            &["old_caller.c", "engine.c"],
        );
        let out = run(&mut Command::new(&exe));
        let stdout = String::from_utf8_lossy(&out.stdout);
        println!("{stdout}");
        assert!(
            stdout.contains(&format!("caller's header: API {version}")),
            "{stdout}"
        );
        assert!(stdout.contains(" 0 failed"), "{stdout}");
    }
}
