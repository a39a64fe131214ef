//! The demo binary as a user runs it: bad input fails with a clear message and a non-zero exit (never a
//! panic); a render on lavapipe writes every promised output with validation on.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hrts-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn host_demo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_host_demo"))
        .args(args)
        .output()
        .expect("host_demo runs")
}

fn render_obj(dir: &Path, obj_text: &str) -> (Output, String) {
    let obj = dir.join("input.obj");
    std::fs::write(&obj, obj_text).expect("write obj");
    let out = dir.join("out");
    let output = host_demo(&[
        "render",
        "--obj",
        obj.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--width",
        "32",
        "--height",
        "32",
    ]);
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    (output, stderr)
}

fn assert_clean_failure(output: &Output, stderr: &str, expect: &str) {
    assert!(
        !output.status.success(),
        "expected failure, stderr: {stderr}"
    );
    assert_eq!(output.status.code(), Some(1), "stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "panicked: {stderr}");
    assert!(stderr.starts_with("error: "), "stderr: {stderr}");
    assert!(stderr.contains(expect), "expected '{expect}' in: {stderr}");
}

#[test]
fn malformed_obj_is_a_clear_error() {
    let dir = temp_dir("malformed");
    for text in [
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n",
        "v 1.0 abc 2.0\n",
        "f 1 2 3\n",
        "garbage \u{0}\u{1} bytes",
    ] {
        let (output, stderr) = render_obj(&dir, text);
        assert_clean_failure(&output, &stderr, "input.obj");
    }
}

#[test]
fn nan_and_inf_vertices_are_rejected() {
    let dir = temp_dir("nan");
    for text in [
        "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n",
        "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n",
    ] {
        let (output, stderr) = render_obj(&dir, text);
        assert_clean_failure(&output, &stderr, "non-finite");
    }
}

#[test]
fn missing_file_and_bad_options_are_clear_errors() {
    let dir = temp_dir("missing");
    let output = host_demo(&["render", "--obj", dir.join("nope.obj").to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_clean_failure(&output, &stderr, "cannot read");
    let output = host_demo(&[
        "render",
        "--light-dir",
        "0,0,0",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_clean_failure(&output, &stderr, "--light-dir");
    let output = host_demo(&[
        "render",
        "--map-budget-mb",
        "0",
        "--width",
        "16",
        "--height",
        "16",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_clean_failure(&output, &stderr, "budget");
}

#[test]
fn render_writes_every_output() {
    let dir = temp_dir("render");
    let out = dir.join("out");
    let output = host_demo(&[
        "--validation",
        "render",
        "--out",
        out.to_str().unwrap(),
        "--width",
        "96",
        "--height",
        "64",
        "--map-size",
        "128",
        "--frames",
        "3",
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "stdout: {stdout}\nstderr: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(
        stdout.contains("ray trace"),
        "timing table missing: {stdout}"
    );
    for f in [
        "frame.json",
        "position.exr",
        "normal.exr",
        "rt_visibility.exr",
        "blocker_distance.exr",
        "occupancy.png",
        "preview.png",
    ] {
        let p = out.join(f);
        assert!(
            p.metadata().map(|m| m.len() > 0).unwrap_or(false),
            "{f} missing or empty"
        );
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("frame.json")).unwrap()).unwrap();
    assert_eq!(json["width"], 96);
    assert_eq!(json["height"], 64);
    assert_eq!(json["camera"]["view"].as_array().unwrap().len(), 16);
    assert_eq!(json["camera"]["proj"].as_array().unwrap().len(), 16);
    assert_eq!(json["light"]["type"], "directional");
    assert_eq!(json["primitive_map"]["size"], 128);
    assert_eq!(json["primitive_map"]["binning_path"], "compute");
    assert_eq!(json["primitive_map"]["texels_past_capacity"], 0);
    assert!(json["primitive_map"]["entries"].as_u64().unwrap() > 0);
    assert!(json["primitive_map"]["longest_list"].as_u64().unwrap() > 0);
    assert!(json["gpu_ms"]["ray trace"].as_f64().unwrap() > 0.0);
    assert!(!json["device"]["name"].as_str().unwrap().is_empty());
}
