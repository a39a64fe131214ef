//! The docs match the program: every relative link (and its `#anchor`) in the README and docs leads
//! somewhere, every flag a command in them names exists in that command's `--help` (host_demo's
//! subcommands, wgpu_host), the outputs the demo guide lists are the files `render` writes, the
//! statistics it names are keys of `frame.json`, and the figures the help and the guide quote come from
//! the code's constants. Edit either side alone and this fails. The dated copies under docs/history are
//! checked for links only: their flags are history.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The demo's guide, docs/demo.md.
fn demo_guide() -> String {
    let path = workspace().join("docs/demo.md");
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}
/// The guide's bullet list that starts after the line `marker` (up to the next blank line).
fn guide_block(guide: &str, marker: &str) -> String {
    let start = guide
        .find(marker)
        .unwrap_or_else(|| panic!("docs/demo.md has no '{marker}'"));
    guide[start + marker.len()..]
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

/// Every file `render` writes by default (hybrid: every image) is listed in docs/demo.md under "`--out` receives:", and
/// every file listed there is written; every key the list names exists
/// in `frame.json`.
#[test]
fn the_demo_guide_lists_what_render_writes() {
    let guide = demo_guide();
    let block = guide_block(&guide, "`--out` receives:");
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
    assert_eq!(
        listed, written,
        "docs/demo.md's list vs the files render wrote"
    );
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
                "docs/demo.md names `{word}`, which frame.json does not have"
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

/// The default light's angle from vertical, as the help and docs/demo.md quote it, is the code's.
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
    let guide = demo_guide().replace('\n', " ");
    assert!(
        guide.contains(&format!("slanted about {angle}° from vertical")),
        "docs/demo.md lacks 'slanted about {angle}° from vertical'"
    );
}

/// The Markdown files a reader meets: README.md, CHANGELOG.md, examples' READMEs and everything under docs/.
fn markdown_files() -> Vec<PathBuf> {
    let root = workspace();
    let mut files = vec![root.join("README.md"), root.join("CHANGELOG.md")];
    let mut stack = vec![root.join("docs"), root.join("examples")];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "md") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// GitHub's anchor of a heading: lower case, punctuation dropped but `-` and `_`, spaces to `-`.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, ' ' | '-' | '_'))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The text outside fenced code blocks, line by line (links in code are not links).
fn prose_lines(text: &str) -> Vec<&str> {
    let mut fenced = false;
    text.lines()
        .filter(|line| {
            if line.trim_start().starts_with("```") {
                fenced = !fenced;
                return false;
            }
            !fenced
        })
        .collect()
}

/// The anchors of a Markdown file's headings (a repeated heading gets `-1`, `-2`, …).
fn anchors(text: &str) -> BTreeSet<String> {
    let mut seen = BTreeMap::<String, usize>::new();
    let mut out = BTreeSet::new();
    for line in prose_lines(text) {
        let Some(heading) = line.strip_prefix('#') else {
            continue;
        };
        let base = slug(heading.trim_start_matches('#').replace('`', "").as_str());
        let n = seen.entry(base.clone()).or_default();
        out.insert(if *n == 0 {
            base.clone()
        } else {
            format!("{base}-{n}")
        });
        *n += 1;
    }
    out
}

/// The targets of inline links and images: `[text](target)` outside code spans and fences.
fn link_targets(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for line in prose_lines(text) {
        let mut in_code = false;
        let bytes: Vec<char> = line.chars().collect();
        let mut i = 0;
        while i < bytes.len() {
            match bytes[i] {
                '`' => in_code = !in_code,
                ']' if !in_code && bytes.get(i + 1) == Some(&'(') => {
                    let rest: String = bytes[i + 2..].iter().collect();
                    if let Some(end) = rest.find(')') {
                        let target = rest[..end].split_whitespace().next().unwrap_or("");
                        out.push(target.to_owned());
                    }
                }
                _ => {}
            }
            i += 1;
        }
    }
    out
}

#[test]
fn every_relative_link_in_the_readme_and_docs_leads_somewhere() {
    let mut checked = 0;
    let mut dead = Vec::new();
    for file in markdown_files() {
        let text = std::fs::read_to_string(&file).unwrap();
        for target in link_targets(&text) {
            if target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            checked += 1;
            let (path, anchor) = target.split_once('#').unwrap_or((&target, ""));
            let resolved = if path.is_empty() {
                file.clone()
            } else {
                file.parent().unwrap().join(path)
            };
            if !resolved.exists() {
                dead.push(format!("{}: {target} (no such file)", file.display()));
                continue;
            }
            if !anchor.is_empty() && resolved.extension().is_some_and(|e| e == "md") {
                let headings = anchors(&std::fs::read_to_string(&resolved).unwrap());
                if !headings.contains(anchor) {
                    dead.push(format!(
                        "{}: {target} (no heading with that anchor)",
                        file.display()
                    ));
                }
            }
        }
    }
    assert!(
        checked > 50,
        "only {checked} links found: is the parser broken?"
    );
    assert!(dead.is_empty(), "dead links:\n{}", dead.join("\n"));
}

/// The flags (`--name`) of a `--help` text, and its subcommands (the lines under `Commands:`).
fn parse_help(help: &str) -> (BTreeSet<String>, Vec<String>) {
    let mut flags = BTreeSet::new();
    let mut commands = Vec::new();
    let mut in_commands = false;
    for line in help.lines() {
        if line.starts_with("Commands:") {
            in_commands = true;
            continue;
        }
        if !line.starts_with(' ') {
            in_commands = false;
        }
        let trimmed = line.trim_start();
        if in_commands {
            if let Some(name) = trimmed.split_whitespace().next() {
                commands.push(name.to_owned());
            }
        } else if trimmed.starts_with('-') {
            for word in trimmed.split(|c: char| c == ',' || c.is_whitespace()) {
                if let Some(name) = word.strip_prefix("--") {
                    let name: String = name
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '-')
                        .collect();
                    flags.insert(name);
                }
            }
        }
    }
    (flags, commands)
}

fn help_of(exe: &Path, args: &[&str]) -> String {
    let out = Command::new(exe)
        .args(args)
        .arg("--help")
        .output()
        .unwrap_or_else(|e| panic!("{}: {e}", exe.display()));
    assert!(
        out.status.success(),
        "{} {args:?} --help failed",
        exe.display()
    );
    String::from_utf8(out.stdout).unwrap()
}

/// The workspace's executable `name` beside host_demo's (wgpu_host's, the lab's), built for the same
/// profile the way the README builds everything (`cargo build --workspace --all-targets`: the features
/// `cargo test --workspace` resolves, so nothing is compiled again).
fn workspace_binary(host_demo: &Path, name: &str) -> PathBuf {
    let dir = host_demo.parent().expect("target/<profile>");
    let mut cargo = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    cargo.args(["build", "--workspace", "--all-targets"]);
    match dir.file_name().and_then(|n| n.to_str()) {
        Some("debug") => {}
        Some(profile) => {
            cargo.args(["--profile", profile]);
        }
        None => panic!("unexpected target folder {}", dir.display()),
    }
    let status = cargo
        .arg("--target-dir")
        .arg(dir.parent().expect("target"))
        .current_dir(workspace())
        .status()
        .expect("cargo runs");
    assert!(
        status.success(),
        "cargo build --workspace --all-targets failed"
    );
    dir.join(name)
}

/// The `--flags` of a command line, up to its end (a `#` comment ends it too).
fn flags_in(words: &[&str]) -> Vec<String> {
    words
        .iter()
        .take_while(|w| !w.starts_with('#'))
        .filter_map(|w| w.trim_start_matches('[').strip_prefix("--"))
        .map(|w| {
            w.chars()
                .take_while(|c| c.is_alphanumeric() || *c == '-')
                .collect::<String>()
        })
        .filter(|w| !w.is_empty())
        .collect()
}

#[test]
fn every_flag_the_readme_and_docs_name_exists() {
    let host_demo = PathBuf::from(env!("CARGO_BIN_EXE_host_demo"));
    let wgpu_host = workspace_binary(&host_demo, "wgpu_host");
    // Per binary with subcommands, the flags of each; the binaries' subcommand names differ, so a span
    // that starts with one (`render --mode area`, `bench --lights`) names its binary.
    let mut by_binary: BTreeMap<&str, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for (name, exe, first) in [
        ("host_demo", host_demo.clone(), "render"),
        (
            "hrts_lab",
            workspace_binary(&host_demo, "hrts_lab"),
            "bench",
        ),
    ] {
        let (global, subcommands) = parse_help(&help_of(&exe, &[]));
        assert!(
            subcommands.contains(&first.to_owned()),
            "{name}: {subcommands:?}"
        );
        let known = by_binary.entry(name).or_default();
        for sub in subcommands.iter().filter(|s| *s != "help") {
            let (flags, _) = parse_help(&help_of(&exe, &[sub]));
            known.insert(sub.clone(), flags.union(&global).cloned().collect());
        }
    }
    let known: BTreeMap<String, BTreeSet<String>> = by_binary
        .values()
        .flat_map(|subs| subs.iter().map(|(k, v)| (k.clone(), v.clone())))
        .collect();
    let (wgpu_flags, _) = parse_help(&help_of(&wgpu_host, &[]));
    let mut checked = 0;
    let mut unknown = Vec::new();
    for file in markdown_files() {
        if file.components().any(|c| c.as_os_str() == "history") {
            continue;
        }
        let text = std::fs::read_to_string(&file).unwrap();
        // Command lines in fenced blocks, and code spans in prose.
        let mut lines: Vec<String> = Vec::new();
        let mut fenced = false;
        for line in text.lines() {
            if line.trim_start().starts_with("```") {
                fenced = !fenced;
            } else if fenced {
                lines.push(line.to_owned());
            } else {
                lines.extend(line.split('`').skip(1).step_by(2).map(str::to_owned));
            }
        }
        for line in lines {
            let words: Vec<&str> = line.split_whitespace().collect();
            let mut i = 0;
            while i < words.len() {
                let w = words[i].trim_start_matches("./");
                let binary = by_binary
                    .iter()
                    .find(|(name, _)| w == **name || w.ends_with(&format!("/{name}")));
                let (flags_known, name, rest) = if let Some((_, subs)) = binary {
                    let mut j = i + 1;
                    if words.get(j) == Some(&"--") {
                        j += 1;
                    }
                    match words.get(j).and_then(|s| subs.get(*s)) {
                        Some(flags) => (flags, words[j], j + 1),
                        None => {
                            i += 1;
                            continue;
                        }
                    }
                } else if (w == "wgpu_host" || w.ends_with("/wgpu_host")) && i + 1 < words.len() {
                    let j = if words[i + 1] == "--" { i + 2 } else { i + 1 };
                    (&wgpu_flags, "wgpu_host", j)
                } else if i == 0 && known.contains_key(w) && words.len() > 1 {
                    // A span such as `render --mode area`.
                    (&known[w], w, 1)
                } else {
                    i += 1;
                    continue;
                };
                for flag in flags_in(&words[rest..]) {
                    checked += 1;
                    if !flags_known.contains(&flag) {
                        unknown.push(format!("{}: {name} --{flag}", file.display()));
                    }
                }
                i = words.len();
            }
        }
    }
    assert!(
        checked > 20,
        "only {checked} flags found: is the parser broken?"
    );
    assert!(
        unknown.is_empty(),
        "flags the commands do not have:\n{}",
        unknown.join("\n")
    );
}
