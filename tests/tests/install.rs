//! The install story as an engine meets it: `scripts/install.sh` installs the plugin under a fresh prefix
//! (reusing this test profile's build), then tests/install/consumer.c is built four ways against the
//! installed files only — pkg-config shared and `--static`, CMake's `hrts::hrts` and `hrts::hrts_static` —
//! and each program creates a context on a device of the plugin's own and prints the device's name.
//! CMake's version file is checked with compatible and incompatible version requests.

mod native;

use native::{compiler, current_build, run, workspace, Build};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// A scratch folder removed when the test ends, whether it passes or fails.
struct TempDir(PathBuf);

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Fails (never skips) when a tool the install story needs is missing.
fn require_tool(tool: &str) {
    let works = Command::new(tool)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    assert!(
        works,
        "`{tool} --version` failed: the install test needs {tool}; run scripts/setup.sh to install it"
    );
}

fn stdout(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Runs a consumer with no library path of the environment (cargo points one at target/<profile>, which
/// holds another libhrts.so): the shared consumers must find the installed library through their rpath.
/// Returns the device name it printed.
fn run_consumer(exe: &Path) -> String {
    let out = run(Command::new(exe).env_remove("LD_LIBRARY_PATH"));
    let text = stdout(&out);
    println!("{}: {}", exe.display(), text.trim());
    let name = text
        .lines()
        .find_map(|l| l.strip_prefix("hrts consumer: device \""))
        .and_then(|rest| rest.split('"').next())
        .unwrap_or_else(|| panic!("{} printed no device name:\n{text}", exe.display()));
    assert!(
        !name.is_empty(),
        "{} printed an empty device name",
        exe.display()
    );
    name.to_owned()
}

/// Whether the executable names `libhrts.so` (a DT_NEEDED entry) anywhere.
fn needs_shared_library(exe: &Path) -> bool {
    let bytes = std::fs::read(exe).unwrap();
    bytes.windows(10).any(|w| w == b"libhrts.so")
}

fn step(name: &str, start: &mut Instant) {
    println!("{name}: {:.1} s", start.elapsed().as_secs_f64());
    *start = Instant::now();
}

#[test]
fn installed_plugin_builds_and_runs_with_pkg_config_and_cmake() {
    require_tool("pkg-config");
    require_tool("cmake");
    let root = workspace();
    let consumer = root.join("tests/install/consumer.c");
    let tmp = TempDir(std::env::temp_dir().join(format!("hrts-install-{}", std::process::id())));
    let _ = std::fs::remove_dir_all(&tmp.0);
    let prefix = tmp.0.join("prefix");
    let lib = prefix.join("lib");
    let mut clock = Instant::now();

    // Install this profile's build (cargo has nothing to rebuild when c_host or an earlier run built it).
    let Build {
        target, profile, ..
    } = current_build();
    let out = run(Command::new("bash")
        .arg(root.join("scripts/install.sh"))
        .arg(&prefix)
        .env("HRTS_PROFILE", &profile)
        .env("CARGO_TARGET_DIR", &target)
        .current_dir(&root));
    assert!(stdout(&out).contains("installed hrts"), "{}", stdout(&out));
    for file in [
        "include/hrts.h",
        "lib/libhrts.so",
        "lib/libhrts.a",
        "lib/pkgconfig/hrts.pc",
        "lib/cmake/hrts/hrtsConfig.cmake",
        "lib/cmake/hrts/hrtsConfigVersion.cmake",
    ] {
        assert!(
            prefix.join(file).is_file(),
            "install.sh did not install {file}"
        );
    }
    step("install.sh", &mut clock);

    let pkg_config = |args: &[&str]| -> Vec<String> {
        let out = run(Command::new("pkg-config")
            .args(args)
            .arg("hrts")
            .env("PKG_CONFIG_PATH", lib.join("pkgconfig")));
        stdout(&out).split_whitespace().map(str::to_owned).collect()
    };
    let version = pkg_config(&["--modversion"]).join("");
    let cflags = pkg_config(&["--cflags"]);
    let cc = |exe: &Path, libs: &[String]| {
        run(Command::new(compiler("cc"))
            .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"])
            .args(&cflags)
            .arg(&consumer)
            .arg("-o")
            .arg(exe)
            .args(libs));
    };

    // (a) pkg-config, shared library.
    let shared = tmp.0.join("consumer_pkg_config_shared");
    let mut libs = pkg_config(&["--libs"]);
    libs.push(format!("-Wl,-rpath,{}", lib.display()));
    cc(&shared, &libs);
    assert!(needs_shared_library(&shared));
    let device = run_consumer(&shared);
    step("pkg-config shared", &mut clock);

    // (b) pkg-config --static, the archive itself in place of -lhrts (the linker would prefer the .so).
    let static_exe = tmp.0.join("consumer_pkg_config_static");
    let mut libs = pkg_config(&["--static", "--libs"]);
    let hrts = libs
        .iter()
        .position(|l| l == "-lhrts")
        .expect("pkg-config --static --libs hrts has -lhrts");
    libs[hrts] = lib.join("libhrts.a").display().to_string();
    cc(&static_exe, &libs);
    assert!(
        !needs_shared_library(&static_exe),
        "{} still needs libhrts.so",
        static_exe.display()
    );
    assert_eq!(run_consumer(&static_exe), device);
    step("pkg-config static", &mut clock);

    // (c) CMake: find_package(hrts <version> REQUIRED), both imported targets.
    let build = tmp.0.join("cmake-build");
    let out = run(Command::new("cmake")
        .arg("-S")
        .arg(root.join("tests/install"))
        .arg("-B")
        .arg(&build)
        .arg(format!("-DCMAKE_PREFIX_PATH={}", prefix.display())));
    let configure = stdout(&out);
    let found = format!(
        "found hrts {version} in {}",
        lib.join("cmake/hrts").display()
    );
    assert!(
        configure.contains(&found),
        "expected `{found}`:\n{configure}"
    );
    run(Command::new("cmake").arg("--build").arg(&build));
    assert!(needs_shared_library(&build.join("consumer_shared")));
    assert!(!needs_shared_library(&build.join("consumer_static")));
    assert_eq!(run_consumer(&build.join("consumer_shared")), device);
    assert_eq!(run_consumer(&build.join("consumer_static")), device);
    step("cmake", &mut clock);

    // hrtsConfigVersion.cmake: SameMajorVersion, as CMake's write_basic_package_version_file writes it.
    let parts: Vec<u32> = version
        .split('.')
        .map(|p| p.parse().expect("numeric version"))
        .collect();
    let (major, minor) = (parts[0], parts[1]);
    let accepted = [
        format!("{major}"),
        format!("{major}.{minor}"),
        version.clone(),
        format!("{major}.{minor}...<{}", major + 1),
    ];
    let rejected = [
        format!("{}", major + 1),
        format!("{major}.{}", minor + 1),
        format!("{major}.{minor}...{}", major + 1),
    ];
    let check = tmp.0.join("version-check");
    std::fs::create_dir_all(&check).unwrap();
    std::fs::write(
        check.join("CMakeLists.txt"),
        format!(
            r#"cmake_minimum_required(VERSION 3.19)
project(hrts_version_check NONE)
foreach(request {accepted})
  find_package(hrts ${{request}} CONFIG QUIET)
  if(NOT hrts_FOUND)
    message(FATAL_ERROR "find_package(hrts ${{request}}) rejected installed ${{hrts_CONSIDERED_VERSIONS}}")
  endif()
endforeach()
foreach(request {rejected})
  find_package(hrts ${{request}} CONFIG QUIET)
  if(hrts_FOUND)
    message(FATAL_ERROR "find_package(hrts ${{request}}) accepted installed ${{hrts_VERSION}}")
  endif()
endforeach()
"#,
            accepted = accepted.join(" "),
            rejected = rejected.join(" "),
        ),
    )
    .unwrap();
    run(Command::new("cmake")
        .arg("-S")
        .arg(&check)
        .arg("-B")
        .arg(check.join("build"))
        .arg(format!("-DCMAKE_PREFIX_PATH={}", prefix.display())));
    step("cmake version file", &mut clock);
    println!("all four consumers ran on {device}");
}
