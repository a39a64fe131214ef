//! The lab binary as a user runs it: bad options fail with a clear message naming the flag; vector
//! options take negative numbers; `bench` takes the user's own models and, off a terminal, never stays
//! silent; `ray-dump` writes the rays `scripts/embree_compare.py` reads.

#[path = "../../host_demo/tests/common/mod.rs"]
mod common;

use common::{assert_clean_failure, temp_dir};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn hrts_lab(args: &[&str]) -> Output {
    common::run(env!("CARGO_BIN_EXE_hrts_lab"), args)
}

/// A unit cube as six quads (12 triangles) in `dir`.
fn cube_obj(dir: &Path) -> PathBuf {
    let path = dir.join("cube.obj");
    std::fs::write(
        &path,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n\
         f 2 4 8 6\nf 1 5 7 3\nf 3 7 8 4\nf 1 2 6 5\nf 5 6 8 7\nf 1 3 4 2\n",
    )
    .expect("write cube.obj");
    path
}

#[test]
fn out_of_range_options_name_the_flag_and_the_range() {
    common::assert_out_of_range_refused(
        env!("CARGO_BIN_EXE_hrts_lab"),
        &[
            (&["tradeoff", "--strata", "-2"], "--strata", "1.."),
            (&["bench", "--frames", "0"], "--frames", "1.."),
            (&["tradeoff", "--height", "99999"], "--height", "1..=16384"),
            (&["ray-dump", "--width", "0"], "--width", "1..=16384"),
        ],
    );
}

/// Vector options take negative numbers as people type them, each value reaching the view.
#[test]
fn vector_options_take_negative_numbers() {
    let dir = temp_dir("negative");
    let out = dir.join("compare");
    let output = hrts_lab(&[
        "compare",
        "--out",
        out.to_str().unwrap(),
        "--width",
        "32",
        "--height",
        "18",
        "--frames",
        "1",
        "--camera-pos",
        "-1,1.5,3.3",
        "--camera-target",
        "0.8,-0.35,0.5",
        "--close-up-pos",
        "-2.3,0.9,2.4",
        "--close-up-target",
        "1.9,-0.1,1.3",
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let caption = std::fs::read_to_string(out.join("caption.txt")).expect("caption.txt");
    for said in [
        "overview camera [-1.0, 1.5, 3.3] -> [0.8, -0.35, 0.5]",
        "close-up [-2.3, 0.9, 2.4] -> [1.9, -0.1, 1.3]",
    ] {
        assert!(caption.contains(said), "'{said}' missing from: {caption}");
    }
}

/// Off a terminal (stderr piped, as in a CI log), a long run prints one plain progress line per step,
/// the first before any GPU work of the first step.
#[test]
fn long_runs_print_a_line_per_step_off_a_terminal() {
    let output = hrts_lab(&[
        "bench",
        "--only",
        "scorpion,plates",
        "--frames",
        "2",
        "--width",
        "48",
        "--height",
        "32",
        "--no-reference",
    ]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    // A step's line is "bench [i/n] <model> (<times>)"; its phases' lines follow the model with ": ".
    let steps: Vec<&str> = stderr
        .lines()
        .filter(|l| {
            l.starts_with("bench [") && l.split(" (").next().is_some_and(|s| !s.contains(": "))
        })
        .collect();
    assert_eq!(steps.len(), 2, "{stderr}");
    assert!(steps[0].starts_with("bench [1/2] 01_scorpion"), "{stderr}");
    assert!(steps[1].starts_with("bench [2/2] 07_veach"), "{stderr}");
    assert!(steps[1].contains("s elapsed, about"), "{stderr}");
    assert!(
        stderr.contains("bench [1/2] 01_scorpion_low_12k.obj: frames 0/2 ("),
        "{stderr}"
    );
}

/// Off a terminal, no long phase is silent: a bench of one model at a low resolution, with the CPU
/// reference, prints its lines (steps, phases, and the state again whenever the interval passes without
/// a line) at most a few intervals apart — the interval shortened to 1 s by `HRTS_PROGRESS_SECONDS` so
/// that a short run shows it (by default 10 s, against the 15 s). Progress per model alone
/// printed one line for the whole model.
#[test]
fn piped_runs_print_a_line_every_interval() {
    use std::io::{BufRead, BufReader, Read};
    use std::time::{Duration, Instant};
    let started = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_hrts_lab"))
        .args([
            "bench",
            "--only",
            "02_stanford",
            "--frames",
            "3",
            "--width",
            "160",
            "--height",
            "90",
        ])
        .env("HRTS_PROGRESS_SECONDS", "1")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("hrts_lab runs");
    let mut stdout = child.stdout.take().expect("stdout");
    let tables = std::thread::spawn(move || {
        let mut text = String::new();
        stdout.read_to_string(&mut text).map(|_| text)
    });
    let mut lines = Vec::new();
    for line in BufReader::new(child.stderr.take().expect("stderr")).lines() {
        lines.push((started.elapsed(), line.expect("a line of stderr")));
    }
    let status = child.wait().expect("hrts_lab ends");
    let ended = started.elapsed();
    let tables = tables.join().expect("stdout read").expect("stdout");
    let log: String = lines
        .iter()
        .map(|(t, l)| format!("{:6.2} s | {l}\n", t.as_secs_f64()))
        .collect();
    assert!(status.success(), "{log}");
    assert!(tables.contains("| 02_stanford_bunny_69k.obj |"), "{tables}");
    let first = lines.first().map_or(ended, |(t, _)| *t);
    assert!(
        first < Duration::from_secs(15),
        "first line after {first:?}:\n{log}"
    );
    let mut times: Vec<Duration> = lines.iter().map(|(t, _)| *t).collect();
    times.push(ended);
    let longest = times
        .windows(2)
        .map(|w| w[1] - w[0])
        .max()
        .unwrap_or_default();
    assert!(
        longest <= Duration::from_secs(4),
        "{longest:?} without a line (interval 1 s):\n{log}"
    );
    for phase in [": frames 0/3 (", ": CPU reference 0/90 ("] {
        assert!(log.contains(phase), "no line of '{phase}':\n{log}");
    }
    assert!(
        lines.len() as f64 >= ended.as_secs_f64() / 2.0,
        "{} lines in {ended:?}:\n{log}",
        lines.len()
    );
}

/// The cells of the Markdown table row of `model` in `tables`.
fn table_row<'a>(tables: &'a str, model: &str) -> Vec<&'a str> {
    let row = tables
        .lines()
        .find(|l| l.starts_with(&format!("| {model} |")))
        .unwrap_or_else(|| panic!("no row of {model} in:\n{tables}"));
    row.trim_matches('|').split('|').map(str::trim).collect()
}

/// `bench` measures a folder of any OBJ files (every .obj in it and its subfolders, in sorted order; a
/// shared model's file name keeps its framing) or the files given to `--obj`, each with the RT-pipeline
/// peer's cells; a folder without .obj files, a missing file and an `--only` that matches nothing are
/// errors that say what was expected, before any GPU work.
#[test]
fn bench_takes_the_users_own_models() {
    let dir = temp_dir("own-models");
    let models = dir.join("models");
    std::fs::create_dir_all(models.join("sub")).unwrap();
    cube_obj(&models);
    std::fs::write(
        models.join("zeta.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(models.join("notes.txt"), "not a model").unwrap();
    let shared = scene::models_dir().unwrap_or_else(|e| panic!("{e}"));
    std::fs::copy(
        shared.join("06_cornell_box/cornell_box.obj"),
        models.join("sub/cornell_box.obj"),
    )
    .unwrap();
    let small = ["--width", "32", "--height", "24", "--frames", "2"];
    let bench = |extra: &[&str]| {
        let mut args = vec!["bench"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&small);
        hrts_lab(&args)
    };

    let output = bench(&["--models", models.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let order: Vec<usize> = ["cube.obj", "sub/cornell_box.obj", "zeta.obj"]
        .iter()
        .map(|m| {
            stdout
                .find(&format!("| {m} |"))
                .unwrap_or_else(|| panic!("no row of {m}:\n{stdout}"))
        })
        .collect();
    assert!(order.windows(2).all(|w| w[0] < w[1]), "{stdout}");
    let cornell = table_row(&stdout, "sub/cornell_box.obj");
    let zeta = table_row(&stdout, "zeta.obj");
    // The shared Cornell box keeps its framing (no ground plane); another file gets a ground plane.
    assert_eq!(cornell[1], "36", "{stdout}");
    assert_eq!(zeta[1], "3", "{stdout}");
    // Every model has the RT-pipeline peer's cells (numbers where the device traces rays).
    assert_eq!(zeta.len(), 16, "{stdout}");
    assert_eq!(zeta[11] == "—", cornell[11] == "—", "{stdout}");

    let zeta_path = models.join("zeta.obj");
    let cube_path = models.join("cube.obj");
    let output = bench(&[
        "--obj",
        zeta_path.to_str().unwrap(),
        cube_path.to_str().unwrap(),
        "--no-reference",
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert_eq!(table_row(&stdout, zeta_path.to_str().unwrap()).len(), 16);
    assert_eq!(table_row(&stdout, cube_path.to_str().unwrap())[1], "14");

    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let missing = dir.join("missing.obj");
    for (args, expect) in [
        (
            vec!["bench", "--models", empty.to_str().unwrap()],
            "no .obj file in",
        ),
        (
            vec!["bench", "--models", models.to_str().unwrap(), "--only", "bunny"],
            "(named by --models): cube.obj, sub/cornell_box.obj, zeta.obj",
        ),
        (
            vec!["bench", "--obj", missing.to_str().unwrap()],
            "missing.obj: no such file",
        ),
        (
            vec!["bench", "--lights", "--models", models.to_str().unwrap()],
            "has no 04_dabrovic_sponza_66k.obj nor 05_conference_clean_277k.obj",
        ),
        (
            vec!["bench", "--lights", "--only", "bunny"],
            "matches none of the scenes of --lights: 04_dabrovic_sponza_66k.obj, 05_conference_clean_277k.obj",
        ),
    ] {
        // No device: the error comes before any GPU work.
        let mut args_with_device = vec!["--device", "no such device"];
        args_with_device.extend(args.iter());
        let output = hrts_lab(&args_with_device);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_clean_failure(&output, &stderr, expect);
        if args.contains(&"--only") {
            assert!(stderr.contains("--only bunny matches none of the "), "{stderr}");
        }
    }
    let output = hrts_lab(&["bench", "--models", empty.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("--obj FILE"), "{stderr}");
}

/// `ray-dump` renders the hard shadow and writes beside it what `scripts/embree_compare.py` reads: the
/// scene's triangles and one ray per pixel that traces one, as many as `rays.json` says, with the GPU's
/// visibility and timings.
#[test]
fn ray_dump_writes_what_the_embree_script_reads() {
    let dir = temp_dir("ray-dump");
    let out = dir.join("dump");
    let output = hrts_lab(&[
        "ray-dump",
        "--out",
        out.to_str().unwrap(),
        "--width",
        "40",
        "--height",
        "30",
        "--frames",
        "2",
        "--light-dir",
        "-0.3,-1,-0.2",
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(stdout.contains("ray dump: "), "{stdout}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("rays.json")).unwrap()).unwrap();
    let count = |key: &str| {
        json[key]
            .as_u64()
            .unwrap_or_else(|| panic!("rays.json lacks {key}: {json}"))
    };
    let size = |name: &str| std::fs::metadata(out.join(name)).map_or(0, |m| m.len());
    let rays = count("rays");
    assert!(rays > 0 && rays <= 40 * 30, "{json}");
    assert_eq!(size("rays.f32"), rays * 8 * 4);
    assert_eq!(size("ray_near_edge.u8"), rays);
    assert_eq!(size("triangles.f32"), count("triangles") * 9 * 4);
    for written in ["rt_visibility.exr", "frame.json"] {
        assert!(size(written) > 0, "{written} missing");
    }
}

/// The sizes the help quotes for `bench` are the plugin's defaults (its choice of N for the default mode,
/// the hybrid).
#[test]
fn bench_help_quotes_the_default_sizes() {
    let output = hrts_lab(&["--help"]);
    let help = String::from_utf8_lossy(&output.stdout).replace('\n', " ");
    let defaults = hrts::Config::default();
    assert_eq!(defaults.mode, hrts::ShadowMode::Hybrid);
    for figure in [
        format!("primitive map {}²", passes::NEAREST_HIT_MAP_SIZE),
        format!("shadow map {}²", defaults.shadow_map_size),
    ] {
        assert!(help.contains(&figure), "hrts_lab --help lacks '{figure}'");
    }
}
