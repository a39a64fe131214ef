//! Renders the built-in scene with the plugin's shadows through wgpu and writes a PNG.

use anyhow::{Context as _, Result};
use clap::Parser;
use hrts::ShadowMode;
use scene::{Camera, DirectionalLight};
use std::path::PathBuf;
use wgpu_host::{validation, Conventions, Gpu, Renderer};

/// The wgpu renderer with the plugin's shadows, on the built-in scene.
#[derive(Parser)]
struct Args {
    /// Output folder.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// Frame width.
    #[arg(long, default_value_t = 1280)]
    width: u32,
    /// Frame height.
    #[arg(long, default_value_t = 720)]
    height: u32,
    /// Hard (ray traced) shadows instead of the hybrid.
    #[arg(long)]
    hard: bool,
    /// Frames to render (the plugin's GPU time is their median after the first).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    frames: u32,
}

fn main() -> Result<()> {
    let args = Args::parse();
    validation::install();
    let gpu = Gpu::new(false)?;
    let scene = scene::procedural_default();
    let mode = if args.hard {
        ShadowMode::Hard
    } else {
        ShadowMode::Hybrid
    };
    let conventions = Conventions::default();
    let mut renderer = Renderer::new(&gpu, &scene, conventions, args.width, args.height, mode)?;
    let mut focus = scene::Aabb::empty();
    for m in renderer.meshes().iter().filter(|m| m.name != "ground") {
        let b = m.bounds(m.rest);
        focus.extend(b.min);
        focus.extend(b.max);
    }
    let camera = Camera::frame(&focus, args.width as f32 / args.height as f32);
    let mut gpu_ms = Vec::new();
    let mut frame = renderer.render(&gpu, &camera, &DirectionalLight::slanted())?;
    for _ in 1..args.frames {
        frame = renderer.render(&gpu, &camera, &DirectionalLight::slanted())?;
        gpu_ms.push(frame.report.gpu_milliseconds);
    }
    gpu_ms.sort_by(f64::total_cmp);
    let gpu_ms = gpu_ms
        .get(gpu_ms.len() / 2)
        .copied()
        .unwrap_or(frame.report.gpu_milliseconds);
    std::fs::create_dir_all(&args.out)?;
    let path = args.out.join("wgpu_host.png");
    let file = std::io::BufWriter::new(std::fs::File::create(&path)?);
    let mut png = png::Encoder::new(file, args.width, args.height);
    png.set_color(png::ColorType::Rgba);
    png.set_depth(png::BitDepth::Eight);
    png.write_header()?
        .write_image_data(&frame.color)
        .context("writing the PNG")?;
    let lit = frame.visibility.iter().filter(|&&v| v > 0.5).count();
    println!(
        "{}: {} meshes, {:?}; {} of {} pixels lit; plugin GPU {:.3} ms ({}); wrote {}",
        gpu.name(),
        renderer.meshes().len(),
        conventions,
        lit,
        frame.visibility.len(),
        gpu_ms,
        if args.frames > 1 {
            format!("median of {} frames after the first", args.frames - 1)
        } else {
            "one frame".to_owned()
        },
        path.display()
    );
    Ok(())
}
