//! `hrts_lab compare`: the talk's side-by-sides on one view — shadow map 3K and 8K, ray traced
//! 1K×1K×64 and ×32, PCSS, and the hybrid with the standard and the shrinking penumbra filter — as
//! individual pictures, one labelled composite and a caption file that states every setting.

use crate::frames::{PluginFrames, ViewInputs};
use anyhow::{bail, Context, Result};
use demo_engine::plugin::PluginRenderer;
use demo_engine::FrameImages;
use demo_engine::View;
use glam::Vec3;
use host_demo::images::{lerp_factor_preview, write_png_compact, Canvas};
use host_demo::output::{shade_preview, write_png};
use host_demo::parse_vec3;
use host_demo::render::median_timings;
use hrts::passes_bridge;
use passes::{
    HybridConfig, PcssConfig, PenumbraFilter, PrimitiveMapConfig, ResourceId, ResourceSet,
    ShadowConfig, ShadowMapConfig, ShadowMode,
};
use rhi::Device;
use scene::Camera;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Options of `hrts_lab compare`.
#[derive(Debug, Clone, clap::Args)]
pub struct CompareArgs {
    /// Output folder (individual pictures, compare.png, caption.txt).
    #[arg(long, default_value = "compare")]
    pub out: PathBuf,
    /// Width of each panel in pixels.
    #[arg(long, default_value_t = 480, value_parser = clap::value_parser!(u32).range(1..=i64::from(host_demo::limits::FRAME_SIDE)))]
    pub width: u32,
    /// Height of each panel in pixels.
    #[arg(long, default_value_t = 270, value_parser = clap::value_parser!(u32).range(1..=i64::from(host_demo::limits::FRAME_SIDE)))]
    pub height: u32,
    /// Camera position "x,y,z" (default: a close-up of the character, the fence and the sphere).
    #[arg(long, value_parser = parse_vec3)]
    pub camera_pos: Option<Vec3>,
    /// Camera target "x,y,z".
    #[arg(long, value_parser = parse_vec3)]
    pub camera_target: Option<Vec3>,
    /// Close-up camera position "x,y,z" (default: the sphere's contact and the end of its shadow).
    #[arg(long, value_parser = parse_vec3)]
    pub close_up_pos: Option<Vec3>,
    /// Close-up camera target "x,y,z".
    #[arg(long, value_parser = parse_vec3)]
    pub close_up_target: Option<Vec3>,
    /// Frames per panel (timings are medians over all but the first).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..))]
    pub frames: u32,
}

/// One panel of the comparison.
struct Panel {
    file: &'static str,
    label: &'static str,
    config: ShadowConfig,
    show: Show,
    note: &'static str,
}

/// Which image of the frame a panel shows.
#[derive(Clone, Copy)]
enum Show {
    ShadowMapTest,
    RayTrace,
    Pcss,
    Output,
    LerpFactor,
}

fn panels(wss: f32) -> Vec<Panel> {
    let map = |size| PrimitiveMapConfig {
        size,
        ..PrimitiveMapConfig::default()
    };
    let sm = |size| ShadowMapConfig {
        size,
        ..ShadowMapConfig::default()
    };
    let pcss = |filter| PcssConfig {
        filter,
        ..PcssConfig::default()
    };
    let hybrid = HybridConfig {
        world_space_scale: wss,
        hard_shadow_percentage: 4.0,
    };
    let base = ShadowConfig {
        static_geometry: true,
        static_light: false,
        hybrid,
        ..ShadowConfig::default()
    };
    let classic = |size| ShadowConfig {
        mode: ShadowMode::None,
        shadow_map: sm(size),
        extra_outputs: ResourceSet::of(&[ResourceId::ShadowMapVisibility]),
        ..base
    };
    let traced = |size| ShadowConfig {
        mode: ShadowMode::Hard,
        antialiasing: false,
        map: map(size),
        ..base
    };
    let hybrid_with = |filter| ShadowConfig {
        mode: ShadowMode::Hybrid,
        antialiasing: true,
        map: map(1024),
        shadow_map: sm(3072),
        pcss: pcss(filter),
        extra_outputs: ResourceSet::of(&[ResourceId::LerpFactor, ResourceId::RtVisibility]),
        ..base
    };
    vec![
        Panel {
            file: "shadow_map_3k.png",
            label: "SHADOW MAP 3K",
            config: classic(3072),
            show: Show::ShadowMapTest,
            note: "classic single-tap shadow-map test, constant + slope-scaled bias of 1 texel each",
        },
        Panel {
            file: "shadow_map_8k.png",
            label: "SHADOW MAP 8K",
            config: classic(8192),
            show: Show::ShadowMapTest,
            note: "same test and bias (in texels) at 8192x8192",
        },
        Panel {
            file: "ray_traced_1k.png",
            label: "RAY TRACED 1K",
            config: traced(1024),
            show: Show::RayTrace,
            note: "primitive map 1024x1024 fitted to the receivers, exact lists, no FXAA",
        },
        Panel {
            file: "ray_traced_256.png",
            label: "RAY TRACED 256",
            config: traced(256),
            show: Show::RayTrace,
            note: "primitive map 256x256: longer lists, the same exact shadow",
        },
        Panel {
            file: "pcss_3k.png",
            label: "PCSS 3K",
            config: ShadowConfig {
                mode: ShadowMode::Soft,
                shadow_map: sm(3072),
                pcss: pcss(PenumbraFilter::Standard),
                ..base
            },
            show: Show::Pcss,
            note: "PCSS, standard filter, 16 blocker-search + 32 PCF taps",
        },
        Panel {
            file: "hybrid_standard.png",
            label: "HYBRID, STANDARD FILTER",
            config: hybrid_with(PenumbraFilter::Standard),
            show: Show::Output,
            note: "lerp(RT with FXAA, PCSS standard, L): the outer half of the penumbra is cut at the hard edge",
        },
        Panel {
            file: "hybrid_shrinking.png",
            label: "HYBRID, SHRINKING FILTER",
            config: hybrid_with(PenumbraFilter::Shrinking),
            show: Show::Output,
            note: "lerp(RT with FXAA, PCSS shrinking, L): the penumbra grows inwards from the hard edge",
        },
        Panel {
            file: "lerp_factor.png",
            label: "LERP FACTOR L",
            config: hybrid_with(PenumbraFilter::Shrinking),
            show: Show::LerpFactor,
            note: "L = saturate(BD / WSS * PHS): black = ray traced, white = PCSS, blue = no blocker",
        },
    ]
}

/// A camera at `position` looking at `target`, overridden by the command line.
fn camera(
    view: &View,
    position: Vec3,
    target: Vec3,
    given: (Option<Vec3>, Option<Vec3>),
) -> Result<Camera> {
    let c = Camera {
        position: given.0.unwrap_or(position),
        target: given.1.unwrap_or(target),
        near: 0.02,
        ..view.camera
    };
    if (c.position - c.target).length() == 0.0 {
        return Err(scene::CoincidentCamera.into());
    }
    Ok(c)
}

/// Runs the comparison on its own device.
pub fn run_cli(device_filter: Option<String>, validation: bool, args: &CompareArgs) -> Result<()> {
    if args.width == 0 || args.height == 0 {
        bail!("--width and --height must be positive");
    }
    let device = demo_engine::open_device(device_filter, validation)?;
    compare_to_folder(&device, args)?;
    demo_engine::check_validation(&device)
}

/// Renders every panel of the procedural scene and writes the pictures, the composite and the caption.
pub fn compare_to_folder(device: &Device, args: &CompareArgs) -> Result<()> {
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let mut view = View::framed(scene::procedural_default(), args.width, args.height);
    // The overview: the character, the fence, the foliage and the sphere's long shadow.
    view.camera = camera(
        &view,
        Vec3::new(2.9, 1.5, 3.3),
        Vec3::new(0.8, 0.35, 0.5),
        (args.camera_pos, args.camera_target),
    )?;
    // The close-up: the sphere's contact with the ground and the far end of its shadow.
    let mut close = view.clone();
    close.camera = camera(
        &view,
        Vec3::new(2.3, 0.9, 2.4),
        Vec3::new(1.9, 0.1, 1.3),
        (args.close_up_pos, args.close_up_target),
    )?;
    let wss = view.scene.world_space_scale();
    let (w, h) = (args.width, args.height);
    let to_light = -view.light.direction;
    let mut pictures = Vec::new();
    let mut caption = String::new();
    let _ = writeln!(
        caption,
        "hrts_lab compare: procedural scene ({} triangles), {w}x{h} per picture, directional light {:?}; \
         overview camera {:?} -> {:?} (top of each panel), close-up {:?} -> {:?} (below it). Previews are \
         Lambert x visibility.\nDevice: {} ({}). GPU times (overview) are medians over {} frames after \
         the first; on a CPU device they are relative only.\n",
        view.scene.triangle_count(),
        view.light.direction.to_array(),
        view.camera.position.to_array(),
        view.camera.target.to_array(),
        close.camera.position.to_array(),
        close.camera.target.to_array(),
        device.capabilities().device_name,
        device.capabilities().device_type,
        args.frames.max(2) - 1,
    );
    for panel in panels(wss) {
        let (frames, timings) = render_panel(device, &[&view, &close], &panel.config, args.frames)
            .with_context(|| format!("rendering panel {}", panel.label))?;
        let pictures_of_panel: Vec<Vec<[u8; 4]>> = frames
            .iter()
            .map(|images| picture(images, panel.show, to_light))
            .collect();
        for (picture, suffix) in pictures_of_panel.iter().zip(["", "_close"]) {
            let file = panel.file.replace(".png", &format!("{suffix}.png"));
            write_png(&args.out.join(file), w, h, picture)?;
        }
        let times: Vec<String> = timings
            .iter()
            .filter(|(name, _)| {
                ["shadow map", "ray trace", "PCSS", "FXAA", "shadow map test"]
                    .contains(&name.as_str())
                    || name.starts_with("primitive map")
            })
            .map(|(name, ms)| format!("{name} {ms:.2} ms"))
            .collect();
        let _ = writeln!(
            caption,
            "{} ({}, close-up in *_close.png): {}. GPU: {}.",
            panel.label,
            panel.file,
            panel.note,
            times.join(", ")
        );
        println!("{:<26} {}", panel.label, times.join(", "));
        pictures.push((panel.label, pictures_of_panel));
    }
    let composite = compose(&pictures, w, h);
    write_png_compact(
        &args.out.join("compare.png"),
        composite.width,
        composite.height,
        &composite.pixels,
    )?;
    std::fs::write(args.out.join("caption.txt"), caption)
        .with_context(|| format!("writing {}/caption.txt", args.out.display()))?;
    println!(
        "wrote {} (composite), the panels and caption.txt",
        args.out.join("compare.png").display()
    );
    Ok(())
}

/// Renders `frames` frames of the first view (for the timings), then one of every view, and reads each
/// back.
fn render_panel(
    device: &Device,
    views: &[&View],
    config: &ShadowConfig,
    frames: u32,
) -> Result<(Vec<FrameImages>, BTreeMap<String, f64>)> {
    let Some(first) = views.first() else {
        bail!("no view to render");
    };
    let mut renderer = PluginRenderer::new(device, first, passes_bridge::config(config)?)?;
    let inputs = first.frame_inputs();
    let mut reports = Vec::new();
    for _ in 0..frames.max(1) {
        reports.push(renderer.render(device, &inputs)?);
    }
    let mut images = vec![renderer.read_back(device, false)?];
    for view in &views[1..] {
        renderer.render(device, &view.frame_inputs())?;
        images.push(renderer.read_back(device, false)?);
    }
    Ok((images, median_timings(&reports)))
}

/// The preview of what a panel shows.
fn picture(images: &FrameImages, show: Show, to_light: Vec3) -> Vec<[u8; 4]> {
    let vis = match show {
        Show::LerpFactor => {
            return lerp_factor_preview(&images.normal, &images.lerp_factor, &images.visibility)
        }
        Show::ShadowMapTest => &images.shadow_map_visibility,
        Show::RayTrace => &images.visibility,
        Show::Pcss => &images.pcss,
        Show::Output => &images.output,
    };
    shade_preview(&images.normal, vis, to_light)
}

/// Panels in a grid of four columns, each under a label bar, its close-up below its overview.
fn compose(panels: &[(&str, Vec<Vec<[u8; 4]>>)], w: u32, h: u32) -> Canvas {
    const COLUMNS: u32 = 4;
    const BAR: u32 = 22;
    const GAP: u32 = 4;
    let views = panels.iter().map(|(_, p)| p.len()).max().unwrap_or(1) as u32;
    let rows = (panels.len() as u32).div_ceil(COLUMNS);
    let cell_h = BAR + views * (h + GAP);
    let mut canvas = Canvas::new(
        COLUMNS * (w + GAP) + GAP,
        rows * cell_h + GAP,
        [24, 24, 24, 255],
    );
    for (i, (label, pictures)) in panels.iter().enumerate() {
        let (col, row) = (i as u32 % COLUMNS, i as u32 / COLUMNS);
        let x = i64::from(GAP + col * (w + GAP));
        let y = i64::from(GAP + row * cell_h);
        canvas.text(x + 4, y + 4, 2, label, [255, 255, 255, 255]);
        for (k, picture) in pictures.iter().enumerate() {
            let top = y + i64::from(BAR) + k as i64 * i64::from(h + GAP);
            canvas.blit(picture, w, h, x, top);
        }
    }
    canvas
}
