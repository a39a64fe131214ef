//! The demo binary as a user runs it: bad input fails with a clear message and a non-zero exit (never a
//! panic); a render on lavapipe writes every promised output with validation on.

mod common;

use common::{assert_clean_failure, temp_dir};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn host_demo(args: &[&str]) -> Output {
    common::run(env!("CARGO_BIN_EXE_host_demo"), args)
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
    // --out naming a file, not a folder.
    let file = dir.join("a-file");
    std::fs::write(&file, "x").expect("write a file");
    let output = host_demo(&["render", "--out", file.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_clean_failure(&output, &stderr, "--out");
    assert!(stderr.contains("is a file"), "{stderr}");
    // An OS error is said once.
    let output = host_demo(&["render", "--obj", dir.join("nope.obj").to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(stderr.matches("os error").count(), 1, "{stderr}");
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

/// Writes the example glTF scene into `dir` through the CLI.
fn example_scene(dir: &Path) -> PathBuf {
    let path = dir.join("example.gltf");
    let output = host_demo(&["example-scene", "--out", path.to_str().unwrap()]);
    assert!(
        output.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    path
}

#[test]
fn malformed_gltf_is_a_clear_error() {
    let dir = temp_dir("malformed-gltf");
    let out = dir.join("out");
    let cases: [(&str, &[u8]); 5] = [
        ("not_json.gltf", b"{ this is not json"),
        ("old.gltf", br#"{"asset": {"version": "1.0"}}"#),
        (
            "bad_accessor.gltf",
            br#"{"asset": {"version": "2.0"}, "meshes": [{"primitives": [{"attributes": {"POSITION": 7}}]}]}"#,
        ),
        ("truncated.glb", b"glTF\x02\x00\x00\x00\xff\x00\x00\x00"),
        ("empty.gltf", br#"{"asset": {"version": "2.0"}}"#),
    ];
    for (name, bytes) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).expect("write scene");
        for command in ["render", "plan"] {
            let mut args = vec![command, "--scene", path.to_str().unwrap()];
            if command == "render" {
                args.extend(["--out", out.to_str().unwrap()]);
            }
            let output = host_demo(&args);
            let stderr = String::from_utf8_lossy(&output.stderr);
            assert_clean_failure(&output, &stderr, path.to_str().unwrap());
        }
    }
    let missing = dir.join("nope.gltf");
    let output = host_demo(&["plan", "--scene", missing.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_clean_failure(&output, &stderr, "nope.gltf");
    let obj = dir.join("model.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("write obj");
    let output = host_demo(&["plan", "--scene", obj.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_clean_failure(&output, &stderr, "--obj");
    let example = example_scene(&dir);
    let output = host_demo(&[
        "render",
        "--scene",
        example.to_str().unwrap(),
        "--frames",
        "1",
    ]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_clean_failure(&output, &stderr, "--frames must be at least 2");
}

#[test]
fn plan_prints_every_light_without_a_device() {
    let dir = temp_dir("plan");
    let example = example_scene(&dir);
    let output = host_demo(&[
        "--device",
        "no such device",
        "plan",
        "--scene",
        example.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "stdout: {stdout}\nstderr: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    for expected in [
        "lights: 5, 4 shadowed by the plugin",
        "[0] sun: directional",
        "-> area (sized sun: exact soft shadows, the visible fraction of 64 light samples within 0.01 rad",
        "[1] rim: directional",
        "-> hard (zero-size light",
        "[2] spot: spot at",
        "[3] fill: point",
        "-> no pass (casts no shadows): visibility 1",
        "[4] cart_lamp: point",
        "-> area (sized point light: exact soft shadows, the visible fraction of 64 samples of its emitter of radius 0.1 m",
        "plugin light 3: one cube map (its six faces built as one primitive map by the plugin",
        "dynamic (not static: cart_body, cart_load)",
    ] {
        assert!(
            stdout.contains(expected),
            "'{expected}' missing in:\n{stdout}"
        );
    }
}

/// Renders the example scene held still (or not) and returns stdout and scene_report.json.
fn render_example(dir: &Path, still: bool) -> (String, serde_json::Value) {
    let example = example_scene(dir);
    let out = dir.join(if still { "still" } else { "moving" });
    let mut args = vec![
        "--validation",
        "render",
        "--scene",
        example.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--width",
        "160",
        "--height",
        "120",
        "--map-size",
        "128",
        "--shadow-map-size",
        "256",
        "--frames",
        "2",
    ];
    if still {
        args.push("--still");
    }
    let output = host_demo(&args);
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(
        output.status.success(),
        "stdout: {stdout}\nstderr: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    for (i, name) in ["sun", "rim", "spot", "fill", "cart_lamp"]
        .iter()
        .enumerate()
    {
        for ext in ["png", "exr"] {
            let p = out.join(format!("visibility_{i}_{name}.{ext}"));
            assert!(p.metadata().is_ok_and(|m| m.len() > 0), "{p:?} missing");
        }
    }
    for f in ["shaded.png", "shaded.exr", "scene_report.json"] {
        assert!(
            out.join(f).metadata().is_ok_and(|m| m.len() > 0),
            "{f} missing"
        );
    }
    let json =
        serde_json::from_str(&std::fs::read_to_string(out.join("scene_report.json")).unwrap())
            .expect("scene_report.json");
    (stdout, json)
}

#[test]
fn scene_render_reports_what_each_light_ran_and_kept() {
    let dir = temp_dir("scene-render");
    let (stdout, json) = render_example(&dir, true);
    assert!(stdout.contains("frame 1: per light"), "{stdout}");
    // The frames summed over the lights: time, the per-pass split and memory.
    assert!(stdout.contains("all 4 lights: GPU "), "{stdout}");
    assert!(stdout.contains("per pass: "), "{stdout}");
    assert!(stdout.contains("memory: the lights' own "), "{stdout}");
    assert!(
        stdout.contains("fill: no pass (casts no shadows)"),
        "{stdout}"
    );
    assert_eq!(json["plugin_lights"], 4);
    let frames = json["frames"].as_array().expect("frames");
    assert_eq!(frames.len(), 2);
    let second = frames[1]["lights"].as_array().expect("lights");
    assert_eq!(second.len(), 4);
    // The lamp is one plugin light with area shadows: its six faces as one cube map.
    let lamp = &second[3];
    assert_eq!(lamp["scene_light"], "cart_lamp");
    assert_eq!(lamp["mode"], "area", "{lamp}");
    assert_eq!(
        lamp["frusta_recorded"].as_u64().unwrap() + lamp["frusta_culled"].as_u64().unwrap(),
        1,
        "{lamp}"
    );
    assert!(
        lamp["decision"]
            .as_str()
            .unwrap()
            .starts_with("point light: "),
        "{lamp}"
    );
    for light in second {
        assert_eq!(light["light_builds"], 1, "{light}");
        assert_eq!(light["pass_status"]["prim buffer"], "UP_TO_DATE", "{light}");
        let expected = if light["mode"] == "hard" || light["mode"] == "area" {
            "NOT_IN_PLAN"
        } else {
            "UP_TO_DATE"
        };
        assert_eq!(light["pass_status"]["shadow map"], expected, "{light}");
        assert_eq!(light["pass_status"]["ray trace"], "RAN", "{light}");
        assert!(
            light["resource_bytes"]["prim list entries"]
                .as_u64()
                .unwrap()
                > 0
        );
    }
    assert_eq!(second[1]["scene_light"], "rim");
    assert!(second[1]["resource_bytes"].get("shadow map").is_none());
    // The sized sun and the sized spot light have exact area shadows (no shadow map).
    for sized in [&second[0], &second[2]] {
        assert_eq!(sized["mode"], "area", "{sized}");
        assert!(
            sized["resource_bytes"].get("shadow map").is_none(),
            "{sized}"
        );
    }

    // As the scene says: the cart moves, so the prim buffer is rebuilt (by the first light, shared by
    // the others) and every primitive map rebuilt.
    let (stdout, json) = render_example(&dir, false);
    assert!(stdout.contains("dynamic (not static: cart_body, cart_load)"));
    let second = json["frames"][1]["lights"].as_array().expect("lights");
    assert_eq!(second[0]["pass_status"]["prim buffer"], "RAN");
    for light in &second[1..] {
        assert_eq!(light["pass_status"]["prim buffer"], "SHARED", "{light}");
        assert_eq!(light["light_builds"], 1, "{light}");
    }
    assert_eq!(second[0]["pass_status"]["ray trace"], "RAN");
    assert_eq!(second[2]["pass_status"]["primitive map"], "RAN");
}

/// Options out of range are refused before any GPU work, naming the flag, the value and the range.
#[test]
fn out_of_range_options_name_the_flag_and_the_range() {
    common::assert_out_of_range_refused(
        env!("CARGO_BIN_EXE_host_demo"),
        &[
            (&["render", "--frames", "0"], "--frames", "1.."),
            (
                &["render", "--map-budget-mb", "0"],
                "--map-budget-mb",
                "1..",
            ),
            (
                &["render", "--map-size", "65536"],
                "--map-size",
                "0..=65535",
            ),
            (&["render", "--width", "0"], "--width", "1..=16384"),
            (&["render", "--width", "-5"], "--width", "1..=16384"),
        ],
    );
}

/// Vector options take negative numbers as people type them (`--camera-pos -5,2,3`, not only
/// `--camera-pos=-5,2,3`), each value reaching the view.
#[test]
fn vector_options_take_negative_numbers() {
    let dir = temp_dir("negative");
    let out = dir.join("render");
    let output = host_demo(&[
        "render",
        "--out",
        out.to_str().unwrap(),
        "--width",
        "32",
        "--height",
        "24",
        "--frames",
        "1",
        "--map-size",
        "64",
        "--shadow-map-size",
        "64",
        "--camera-pos",
        "-5,2,3",
        "--camera-target",
        "0,-0.5,0",
        "--light-dir",
        "-0.3,-1,-0.2",
    ]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("frame.json")).unwrap()).unwrap();
    let floats = |v: &serde_json::Value| -> Vec<f64> {
        v.as_array()
            .unwrap_or_else(|| panic!("not an array: {v}"))
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    assert_eq!(floats(&json["camera"]["position"]), [-5.0, 2.0, 3.0]);
    // The target lies on the view's axis: x and y of the view-space target are 0.
    let view = floats(&json["camera"]["view"]);
    let target = [0.0, -0.5, 0.0, 1.0];
    for row in 0..2 {
        let v: f64 = (0..4).map(|col| view[col * 4 + row] * target[col]).sum();
        assert!(v.abs() < 1e-4, "target off the view axis: {view:?}");
    }
    let light = floats(&json["light"]["direction"]);
    let given = [-0.3f64, -1.0, -0.2];
    let norm = given.iter().map(|c| c * c).sum::<f64>().sqrt();
    for (l, g) in light.iter().zip(given) {
        assert!((l - g / norm).abs() < 1e-5, "light direction {light:?}");
    }

    let example = example_scene(&dir);
    let output = host_demo(&[
        "plan",
        "--scene",
        example.to_str().unwrap(),
        "--camera-pos",
        "-5,2,3",
        "--camera-target",
        "-1,0,-0.5",
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(stdout.contains("camera from the command line"), "{stdout}");
}

/// Without a Vulkan driver, the error says how to get one.
#[test]
fn no_vulkan_driver_names_the_setup_script() {
    let dir = temp_dir("no-driver");
    let output = Command::new(env!("CARGO_BIN_EXE_host_demo"))
        .args(["render", "--width", "16", "--height", "16", "--out"])
        .arg(dir.join("out"))
        .env("VK_ICD_FILENAMES", dir.join("no-such-driver.json"))
        .env("VK_DRIVER_FILES", dir.join("no-such-driver.json"))
        .output()
        .expect("host_demo runs");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_clean_failure(&output, &stderr, "scripts/setup.sh");
    assert!(stderr.contains("lavapipe"), "{stderr}");
}

/// Reads an 8-bit PNG (grey or RGBA) into its first channel per pixel.
fn png_first_channel(path: &Path) -> Vec<u8> {
    let decoder = png::Decoder::new(std::fs::File::open(path).expect("png exists"));
    let mut reader = decoder.read_info().expect("png header");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("png frame");
    let channels = info.color_type.samples();
    buf[..info.buffer_size()]
        .chunks_exact(channels)
        .map(|p| p[0])
        .collect()
}

/// The shared conference room is closed: by default `render` looks at it from inside, in free space,
/// and lights it with a point light inside, so the frame shows lit floor and walls and the shadows of
/// the furniture (it used to show the outside of the box, and a sun cannot light it).
#[test]
fn a_closed_model_is_seen_and_lit_from_inside_by_default() {
    let models = scene::models_dir().unwrap_or_else(|e| panic!("{e}"));
    let obj = models.join("05_conference_clean_277k.obj");
    let bounds = scene::load_obj(&obj)
        .unwrap_or_else(|e| panic!("{e}"))
        .bounds();
    let dir = temp_dir("closed-conference");
    let out = dir.join("out");
    let output = host_demo(&[
        "--validation",
        "render",
        "--obj",
        obj.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--width",
        "160",
        "--height",
        "90",
        "--frames",
        "2",
        "--map-size",
        "128",
        "--shadow-map-size",
        "256",
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "stdout: {stdout}\nstderr: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let first = stdout.lines().next().unwrap_or_default();
    for said in [
        "closed scene: ",
        "% of the ",
        "camera inside at (",
        "point light at (",
    ] {
        assert!(first.contains(said), "'{said}' missing from: {first}");
    }
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("scene_report.json")).expect("scene_report.json"),
    )
    .expect("scene_report.json parses");
    for point in ["position", "target"] {
        let p: Vec<f32> = json["camera"][point]
            .as_array()
            .unwrap_or_else(|| panic!("camera {point} missing: {json}"))
            .iter()
            .map(|v| v.as_f64().unwrap() as f32)
            .collect();
        let p = glam::Vec3::from_slice(&p);
        assert!(
            p.cmpgt(bounds.min).all() && p.cmplt(bounds.max).all(),
            "camera {point} {p} is outside the model's bounds {bounds:?}"
        );
    }
    let visibility = png_first_channel(&out.join("visibility_0_interior.png"));
    assert_eq!(visibility.len(), 160 * 90);
    let share = |keep: fn(u8) -> bool| {
        visibility.iter().filter(|&&v| keep(v)).count() as f64 / visibility.len() as f64
    };
    let (lit, shadowed) = (share(|v| v >= 250), share(|v| v <= 5));
    assert!(lit > 0.2, "only {lit:.3} of the frame is lit");
    assert!(
        shadowed > 0.02,
        "only {shadowed:.3} of the frame is in shadow"
    );
    let shaded = png_first_channel(&out.join("shaded.png"));
    assert!(shaded.iter().any(|&v| v > 128), "the shaded frame is dark");
}

/// A generated room (its walls facing in, a table inside), as an OBJ file.
fn room_obj(dir: &Path) -> PathBuf {
    let mut text = String::new();
    let boxes = [
        ([-3.0, 0.0, -2.0], [5.0, 3.0, 4.0], true),
        ([-0.5, 0.0, 0.0], [2.5, 0.8, 2.0], false),
    ];
    for (k, (lo, hi, inward)) in boxes.iter().enumerate() {
        for i in 0..8 {
            let pick = |axis: usize| {
                if i >> axis & 1 == 1 {
                    hi[axis]
                } else {
                    lo[axis]
                }
            };
            text += &format!("v {} {} {}\n", pick(0), pick(1), pick(2));
        }
        // Corner i is at max along x, y, z where bit 0, 1, 2 of i is set; faces wound outwards.
        let faces = [
            [1, 3, 7, 5],
            [0, 4, 6, 2],
            [2, 6, 7, 3],
            [0, 1, 5, 4],
            [4, 5, 7, 6],
            [0, 2, 3, 1],
        ];
        for face in faces {
            let mut f: Vec<usize> = face.iter().map(|v| v + 1 + 8 * k).collect();
            if *inward {
                f.reverse();
            }
            text += &format!("f {} {} {} {}\n", f[0], f[1], f[2], f[3]);
        }
    }
    let path = dir.join("room.obj");
    std::fs::write(&path, text).expect("write room.obj");
    path
}

/// On a closed model, `--light-dir` keeps the sun (with the camera inside), and the options only a sun
/// has fail clearly with the interior light; an open model says why it is framed from outside.
#[test]
fn closed_model_options_and_open_models() {
    let dir = temp_dir("closed-options");
    let room = room_obj(&dir);
    let run_obj = |obj: &Path, extra: &[&str], out: &str| {
        let out = dir.join(out);
        let mut args = vec![
            "render",
            "--obj",
            obj.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--width",
            "32",
            "--height",
            "24",
            "--frames",
            "1",
            "--map-size",
            "64",
            "--shadow-map-size",
            "64",
        ];
        args.extend_from_slice(extra);
        let output = host_demo(&args);
        let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
        let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
        (output, stdout, stderr, out)
    };
    let run = |extra: &[&str], out: &str| run_obj(&room, extra, out);
    let (output, stdout, stderr, out) = run(&["--mode", "hard"], "point");
    assert!(output.status.success(), "{stdout}\n{stderr}");
    assert!(
        stdout.starts_with("closed scene: 100.0% of the "),
        "{stdout}"
    );
    assert!(stdout.contains("zero size"), "{stdout}");
    assert!(out.join("shaded.png").is_file());

    let (output, stdout, stderr, out) = run(&["--light-dir", "0,-1,0"], "sun");
    assert!(output.status.success(), "{stdout}\n{stderr}");
    assert!(stdout.contains("the sun of --light-dir"), "{stdout}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("frame.json")).unwrap()).unwrap();
    let position: Vec<f64> = json["camera"]["position"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert!(
        (-3.0..5.0).contains(&position[0])
            && (0.0..3.0).contains(&position[1])
            && (-2.0..4.0).contains(&position[2]),
        "camera at {position:?} is not in the room"
    );

    let (output, _, stderr, _) = run(&["--mode", "soft"], "refused");
    assert_clean_failure(&output, &stderr, "--mode soft");

    let cube = dir.join("cube.obj");
    std::fs::write(
        &cube,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n\
         f 2 4 8 6\nf 1 5 7 3\nf 3 7 8 4\nf 1 2 6 5\nf 5 6 8 7\nf 1 3 4 2\n",
    )
    .unwrap();
    let (output, stdout, _, out) = run_obj(&cube, &[], "cube");
    assert!(output.status.success(), "{stdout}");
    assert!(stdout.starts_with("open scene: "), "{stdout}");
    assert!(out.join("preview.png").is_file());
}
