//! `load-report`: what loading a glTF scene costs (wall time and the process's peak resident
//! memory), and the generated test scenes to measure it on (float, meshopt, quantized + meshopt).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use glam::Vec3;
use scene::gltf_scene::{write_scene, GltfEncoding, Quantization, QuantizedComponent};
use scene::{LightKind, LightSize, MeshBuilder, Scene, SceneFile, SceneLight};

/// Arguments of `load-report`.
#[derive(clap::Args)]
pub struct LoadReportArgs {
    /// glTF scene to load once; prints the load time and the peak resident memory of the process
    /// (VmHWM), so run one load per process.
    #[arg(long, required_unless_present = "generate")]
    pub scene: Option<PathBuf>,
    /// Instead, write a terrain of about this many triangles, in 16 objects with a sun, as
    /// `float.glb`, `meshopt.glb` and `quantized-meshopt.glb` into --out.
    #[arg(long, requires = "out", conflicts_with = "scene")]
    pub generate: Option<u32>,
    /// Folder for --generate.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Runs `load-report`.
pub fn run_cli(args: &LoadReportArgs) -> Result<()> {
    match (&args.scene, args.generate, &args.out) {
        (Some(path), _, _) => report(path),
        (None, Some(triangles), Some(out)) => generate(triangles, out),
        _ => bail!("give --scene FILE, or --generate TRIANGLES --out DIR"),
    }
}

fn report(path: &Path) -> Result<()> {
    let start = Instant::now();
    let file = scene::load_gltf(path)?;
    let seconds = start.elapsed().as_secs_f64();
    let bytes = std::fs::metadata(path)?.len();
    println!(
        "{}: {} bytes, {} triangles, {} vertices, {} objects, {} lights",
        path.display(),
        bytes,
        file.scene.triangle_count(),
        file.scene.positions.len(),
        file.scene.objects.len(),
        file.lights.len()
    );
    println!("load time: {:.1} ms", seconds * 1e3);
    match peak_resident_kib() {
        Some(kib) => println!(
            "peak resident memory (VmHWM): {:.1} MiB",
            kib as f64 / 1024.0
        ),
        None => println!("peak resident memory: not available (no /proc/self/status VmHWM)"),
    }
    Ok(())
}

/// `VmHWM` of /proc/self/status, in KiB.
fn peak_resident_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// A rolling terrain of about `triangles` triangles in 16 square tiles, and a sun.
fn terrain(triangles: u32) -> SceneFile {
    let tiles = 4u32;
    let per_tile = (triangles / (tiles * tiles * 2)).max(1);
    let cells = (per_tile as f64).sqrt().ceil() as u32;
    let size = 64.0;
    let step = size / (tiles * cells) as f32;
    let height = |x: f32, z: f32| 0.8 * (x * 0.37).sin() * (z * 0.23).cos() + 0.1 * (x * 3.1).sin();
    let mut scene = Scene::default();
    for tx in 0..tiles {
        for tz in 0..tiles {
            let mut mesh = MeshBuilder::new();
            for i in 0..=cells {
                for j in 0..=cells {
                    let x = (tx * cells + i) as f32 * step - size / 2.0;
                    let z = (tz * cells + j) as f32 * step - size / 2.0;
                    mesh.vertex(Vec3::new(x, height(x, z), z));
                }
            }
            let at = |i: u32, j: u32| i * (cells + 1) + j;
            for i in 0..cells {
                for j in 0..cells {
                    mesh.connect_quad([at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)]);
                }
            }
            scene.append(&mesh.into_scene(&format!("tile_{tx}_{tz}")));
        }
    }
    let objects = scene.objects.len();
    SceneFile {
        scene,
        static_objects: vec![true; objects],
        shadow_casters: vec![true; objects],
        lights: vec![SceneLight {
            name: "sun".into(),
            kind: LightKind::Directional {
                direction: Vec3::new(0.4, -1.0, 0.3).normalize(),
            },
            color: Vec3::ONE,
            intensity: 3.0,
            size: LightSize::Zero,
            casts_shadows: true,
            is_static: true,
        }],
        camera: None,
        skipped_primitives: 0,
    }
}

fn generate(triangles: u32, out: &Path) -> Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let file = terrain(triangles);
    let quantize = Some(Quantization {
        component: QuantizedComponent::U16,
        normalized: true,
    });
    for (name, encoding) in [
        ("float.glb", GltfEncoding::default()),
        (
            "meshopt.glb",
            GltfEncoding {
                quantize: None,
                meshopt: true,
            },
        ),
        (
            "quantized-meshopt.glb",
            GltfEncoding {
                quantize,
                meshopt: true,
            },
        ),
    ] {
        let path = out.join(name);
        write_scene(&path, &file, encoding)?;
        println!(
            "{}: {} triangles, {} bytes",
            path.display(),
            file.scene.triangle_count(),
            std::fs::metadata(&path)?.len()
        );
    }
    Ok(())
}
