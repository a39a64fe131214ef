//! The C ABI as an engine uses it: a plain C program (tests/c_host/c_host.c, with the engine it shares
//! with the other C tests, engine.c), built here with the system compiler against the generated header
//! and the plugin's shared library, creates its own Vulkan device, fills depth and normal images itself,
//! records the plugin into its command buffer and checks the visibility against the exact shadow, then
//! runs the misuse cases and 100 create/destroy cycles.

mod native;

use native::{compiler, library_dir, run, workspace};
use std::process::Command;

#[test]
fn header_compiles_as_c99_and_cxx() {
    let include = workspace().join("plugin_api/include");
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

#[test]
fn c_host_matches_the_exact_shadow_and_survives_misuse() {
    let root = workspace();
    let lib = library_dir();
    let exe = std::env::temp_dir().join(format!("hrts-c-host-{}", std::process::id()));
    run(Command::new(compiler("cc"))
        .args(["-std=c99", "-O1", "-Wall", "-Wextra", "-Werror"])
        .arg("-I")
        .arg(root.join("plugin_api/include"))
        .arg(root.join("tests/c_host/c_host.c"))
        .arg(root.join("tests/c_host/engine.c"))
        .arg("-o")
        .arg(&exe)
        .arg("-L")
        .arg(&lib)
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .args(["-lhrts", "-lvulkan", "-lm"]));
    let out = run(&mut Command::new(&exe));
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    assert!(stdout.contains(" 0 failed"), "{stdout}");
    assert!(stdout.contains(", 0 mismatches"), "{stdout}");
}
