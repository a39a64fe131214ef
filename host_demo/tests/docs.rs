//! The docs match the program: the outputs the README lists are the files `render` writes, the
//! statistics it names are keys of `frame.json`, and the figures the help and the README quote come from
//! the code's constants. Edit either side alone and this fails.

use std::collections::BTreeSet;
use std::path::PathBuf;
use std::process::Command;

fn readme() -> String {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../README.md");
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The README's bullet list that starts after the line `marker` (up to the next blank line).
fn readme_block(readme: &str, marker: &str) -> String {
    let start = readme
        .find(marker)
        .unwrap_or_else(|| panic!("the README has no '{marker}'"));
    readme[start + marker.len()..]
        .split("\n\n")
        .next()
        .unwrap_or_default()
        .to_owned()
}

/// The `backticked` words of `text`.
fn backticked(text: &str) -> Vec<String> {
    text.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_owned)
        .collect()
}

fn host_demo(args: &[&str]) -> String {
    let output = Command::new(env!("CARGO_BIN_EXE_host_demo"))
        .args(args)
        .output()
        .expect("host_demo runs");
    assert!(
        output.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// Every file `render` writes by default (hybrid: every image) is listed under "`--out` receives:", and
/// every file listed there is written (the `--dump-rays` files aside); every key the list names exists
/// in `frame.json`.
#[test]
fn the_readme_lists_what_render_writes() {
    let readme = readme();
    let block = readme_block(&readme, "`--out` receives:");
    let listed: BTreeSet<String> = backticked(&block)
        .into_iter()
        .filter(|w| w.ends_with(".exr") || w.ends_with(".png") || w.ends_with(".json"))
        .filter(|w| !w.contains('/'))
        .collect();
    let out = std::env::temp_dir().join(format!("hrts-docs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    host_demo(&[
        "render",
        "--width",
        "48",
        "--height",
        "32",
        "--map-size",
        "64",
        "--frames",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    let written: BTreeSet<String> = std::fs::read_dir(&out)
        .expect("output folder")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(listed, written, "README list vs the files render wrote");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("frame.json")).unwrap()).unwrap();
    let mut keys = BTreeSet::new();
    collect_keys(&json, &mut keys);
    let frame_json = block
        .split("\n- ")
        .find(|item| item.contains("frame.json"))
        .expect("a frame.json item");
    for word in backticked(frame_json) {
        if word != "frame.json" {
            assert!(
                keys.contains(&word),
                "the README names `{word}`, which frame.json does not have"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&out);
}

fn collect_keys(value: &serde_json::Value, keys: &mut BTreeSet<String>) {
    match value {
        serde_json::Value::Object(map) => {
            for (k, v) in map {
                keys.insert(k.clone());
                collect_keys(v, keys);
            }
        }
        serde_json::Value::Array(items) => items.iter().for_each(|v| collect_keys(v, keys)),
        _ => {}
    }
}

/// The default light's angle from vertical, as the help and the README quote it, is the code's.
#[test]
fn the_default_light_angle_is_quoted_from_the_code() {
    let angle = scene::DirectionalLight::slanted()
        .direction
        .angle_between(glam::Vec3::NEG_Y)
        .to_degrees()
        .round();
    let quoted = format!("about {angle}° from vertical");
    let help = host_demo(&["render", "--help"]);
    assert!(help.contains(&quoted), "render --help lacks '{quoted}'");
    let readme = readme().replace('\n', " ");
    assert!(
        readme.contains(&format!("slanted about {angle}° from vertical")),
        "the README lacks 'slanted about {angle}° from vertical'"
    );
}

/// The sizes the help quotes for `bench` are the defaults of the code.
#[test]
fn bench_help_quotes_the_default_sizes() {
    let help = host_demo(&["--help"]).replace('\n', " ");
    let map = passes::PrimitiveMapConfig::default().size;
    let shadow_map = passes::ShadowMapConfig::default().size;
    for figure in [
        format!("primitive map {map}²"),
        format!("shadow map {shadow_map}²"),
    ] {
        assert!(help.contains(&figure), "host_demo --help lacks '{figure}'");
    }
}
