//! The C ABI as an engine uses it: a plain C program (tests/c_host/c_host.c), built here with the system
//! compiler against the generated header and the plugin's shared library, creates its own Vulkan device,
//! fills depth and normal images itself, records the plugin into its command buffer and checks the
//! visibility against the exact shadow, then runs the misuse cases and 100 create/destroy cycles.

use std::path::{Path, PathBuf};
use std::process::Command;

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The folder holding `libhrts.so` for this build profile (target/<profile>), building the plugin's
/// shared library there first: `cargo test` builds only the rlib of a dependency.
fn library_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    let dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("target/<profile>/deps/<test>")
        .to_path_buf();
    let target = dir.parent().expect("target/<profile>").to_path_buf();
    let profile = match dir.file_name().and_then(|n| n.to_str()) {
        Some("debug") => "dev".to_owned(),
        Some(other) => other.to_owned(),
        None => panic!("unexpected target folder {}", dir.display()),
    };
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    run(Command::new(cargo)
        .args([
            "build",
            "-p",
            "plugin_api",
            "--profile",
            &profile,
            "--target-dir",
        ])
        .arg(&target)
        .current_dir(workspace()));
    assert!(
        dir.join("libhrts.so").exists(),
        "libhrts.so not found in {} after building plugin_api",
        dir.display()
    );
    dir
}

fn compiler(name: &str) -> String {
    std::env::var(name.to_uppercase()).unwrap_or_else(|_| name.to_owned())
}

fn run(cmd: &mut Command) -> std::process::Output {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("cannot run {cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{cmd:?} failed\nstdout:\n{}\nstderr:\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

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
