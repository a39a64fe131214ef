//! `host_demo render --scene`: a glTF scene's lights through the plugin's C ABI as the scene's plan
//! ([`crate::scene_plan`]) says, each shadowed light one light of the plugin, the shaded image and every
//! light's visibility, and per frame and light what ran, what was culled or reused and why, and the
//! memory it holds.

use crate::output::{write_exr_rgba, write_exr_scalar, write_png};
use crate::report_text::{resource_bytes, routes_line};
use crate::scene_plan::{PlannedScene, ScenePlan};
use crate::shading::{shade, tone_map};
use anyhow::{Context, Result};
use demo_engine::gbuffer::GBufferLayout;
use demo_engine::plugin::{LightsFrame, PluginRenderer};
use demo_engine::{CameraMatrices, Device, FrameImages};
use glam::Vec3;
use hrts::{FrameReport, MapStats, Pass, PassStatus};
use scene::{Camera, SceneFile};
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

/// Linear radiance of the background of the shaded image (a pale blue sky once tone mapped).
const SKY_RADIANCE: Vec3 = Vec3::new(0.35, 0.5, 0.8);

/// A scene's frames through the plugin.
pub struct SceneRenderer {
    plugin: PluginRenderer,
    width: u32,
    height: u32,
}

/// A frame read back: the G-buffer and the visibility of every light.
#[derive(Debug, Clone, Default)]
pub struct SceneImages {
    /// The demo's G-buffer (position, normal, depth).
    pub gbuffer: FrameImages,
    /// Per scene light: its layer of the plugin's visibility image, or 1 everywhere for a light without
    /// a pass.
    pub visibility: Vec<Vec<f32>>,
    /// Per plugin light: its layer of the visibility image.
    pub layers: Vec<Vec<f32>>,
}

impl SceneRenderer {
    /// Uploads `file`'s scene and creates the G-buffer and a plugin context for a `width` x `height`
    /// frame. Every object is drawn; the plugin is given the objects that cast shadows
    /// (`SceneFile::shadow_casters`).
    pub fn new(device: &Device, file: &SceneFile, width: u32, height: u32) -> Result<Self> {
        let plugin = PluginRenderer::for_scene_casters(
            device,
            &file.scene,
            &file.shadow_casters,
            width,
            height,
            GBufferLayout::ANALYSIS,
        )?;
        Ok(Self {
            plugin,
            width,
            height,
        })
    }

    /// Has each light write its layer of the visibility image directly
    /// ([`PluginRenderer::write_outputs_directly`]); call before the first frame.
    pub fn write_outputs_directly(&mut self) {
        self.plugin.write_outputs_directly();
    }

    /// The plugin driver.
    pub fn plugin(&self) -> &PluginRenderer {
        &self.plugin
    }

    /// The plugin driver, to set what it draws into before the first frame (such as
    /// [`PluginRenderer::set_output_format`]).
    pub fn plugin_mut(&mut self) -> &mut PluginRenderer {
        &mut self.plugin
    }

    /// Renders one frame of `plan` seen through `camera`: configures the plugin with the plan's lights
    /// (unchanged lights keep their passes) and records them. Returns the plugin's report per light.
    pub fn render(
        &mut self,
        device: &Device,
        camera: &Camera,
        plan: &ScenePlan,
    ) -> Result<LightsFrame> {
        self.plugin
            .configure_lights(device, &plan.plugin_configs())?;
        self.plugin.render_lights(
            device,
            &CameraMatrices::of_camera(camera, self.width, self.height),
            &plan.plugin_frame_lights(),
        )
    }

    /// Reads back the last frame: the G-buffer, every plugin light's layer and every scene light's
    /// visibility.
    pub fn read_back(&self, device: &Device, plan: &ScenePlan) -> Result<SceneImages> {
        let (gbuffer, layers) = self.plugin.read_frame(device)?;
        let pixels = self.width as usize * self.height as usize;
        let mut visibility = vec![vec![1.0f32; pixels]; plan.lights.len()];
        for (light, layer) in plan.plugin_lights().iter().zip(&layers) {
            visibility[light.scene_light].clone_from(layer);
        }
        Ok(SceneImages {
            gbuffer,
            visibility,
            layers,
        })
    }
}

/// Why a light's light-space passes ran or were reused this frame.
fn light_space_reason(
    report: &FrameReport,
    built_now: bool,
    static_light: bool,
    dynamic_geometry: bool,
) -> String {
    if report.frusta == 0 {
        return format!("nothing recorded: {}", report.decision_reason);
    }
    if built_now {
        return format!(
            "passes built this frame (build {}): everything in the plan ran",
            report.light_builds
        );
    }
    let prims = match report.status(Pass::PrimBuffer) {
        PassStatus::Ran => "prim buffer rebuilt by this light (dynamic geometry)",
        PassStatus::Shared => {
            "prim buffer rebuilt this frame by an earlier light (dynamic geometry)"
        }
        _ => "prim buffer reused (static geometry)",
    };
    let shadow_map = match report.status(Pass::ShadowMap) {
        PassStatus::Ran if dynamic_geometry => "shadow map re-rendered: the geometry moves",
        PassStatus::Ran if !static_light => "shadow map re-rendered: the light is not static",
        PassStatus::Ran => "shadow map re-rendered: the light changed",
        PassStatus::UpToDate => {
            "shadow map reused: a static light over static geometry, unchanged since it ran"
        }
        _ => "no shadow map in the plan",
    };
    let culled = match report.frusta_culled {
        0 => String::new(),
        _ => format!("; {}", report.decision_reason),
    };
    format!("{prims}; {shadow_map}; the primitive map is refitted to the view every frame{culled}")
}

/// `bytes` in KiB or MiB.
fn size(bytes: u64) -> String {
    if bytes < 1 << 20 {
        format!("{:.1} KiB", bytes as f64 / 1024.0)
    } else {
        format!("{:.2} MiB", bytes as f64 / f64::from(1 << 20))
    }
}

/// GPU milliseconds of a light's passes this frame (all of them, and per pass).
fn gpu_ms(report: &FrameReport) -> (f64, BTreeMap<String, f64>) {
    let per_pass: BTreeMap<String, f64> = report
        .timings
        .iter()
        .map(|t| (t.name.clone(), t.milliseconds))
        .collect();
    (
        report.timings.iter().map(|t| t.milliseconds).sum(),
        per_pass,
    )
}

/// A light's GPU time and list statistics on one line.
fn describe_cost(report: &FrameReport) -> String {
    let (total, per_pass) = gpu_ms(report);
    let passes: Vec<String> = per_pass
        .iter()
        .map(|(name, ms)| format!("{name} {ms:.3}"))
        .collect();
    let st = &report.stats;
    format!(
        "GPU {total:.3} ms ({}); lists: {} receiver px, {} triangles binned, {} entries, mean {:.1} / longest {}; {}",
        passes.join(", "),
        st.receiver_pixels,
        st.triangles_binned,
        st.entries,
        st.mean_list(),
        st.longest_list,
        routes_line(st, &per_pass)
    )
}

/// What a frame did, per light, as text: for each light what the plan gave it and the memory it holds,
/// and for each of its frusta the pass statuses, how many times its passes were built, why its
/// light-space passes ran or were reused, and the memory of each resource; lights without a pass say so.
/// `previous` is the frame before (its builds tell which lights were rebuilt).
pub fn describe_frame(
    plan: &ScenePlan,
    frame: &LightsFrame,
    previous: Option<&LightsFrame>,
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "frame {}: per light (pass statuses RAN / UP_TO_DATE / SHARED / NOT_IN_PLAN / CULLED)",
        frame.frame_index
    );
    let plugin_lights = plan.plugin_lights();
    for (i, light) in plan.lights.iter().enumerate() {
        let mine = plugin_lights
            .iter()
            .position(|l| l.scene_light == i)
            .and_then(|k| frame.lights.get(k).map(|r| (k, r)));
        let (Some(shadowed), Some((k, report))) = (light.shadowed(), mine) else {
            let _ = writeln!(
                s,
                "  {}: {}; holds nothing",
                light.light.name,
                light.describe_decision()
            );
            continue;
        };
        let built_now = previous
            .and_then(|p| p.lights.get(k))
            .is_none_or(|p| p.light_builds != report.light_builds);
        let _ = writeln!(
            s,
            "  {} (plugin light {k}): {}, {} of {} frust{} recorded, holds {}; passes built {} time{}",
            light.light.name,
            shadowed.resolved_config().mode.name(),
            report.frusta,
            shadowed.frusta.len(),
            if shadowed.frusta.len() == 1 { "um" } else { "a" },
            size(own_bytes(report)),
            report.light_builds,
            if report.light_builds == 1 { "" } else { "s" }
        );
        let mut by_status: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
        for pass in hrts::PassMask::ALL.iter() {
            by_status
                .entry(report.status(pass).name())
                .or_default()
                .push(pass.name());
        }
        for name in ["RAN", "UP_TO_DATE", "SHARED", "NOT_IN_PLAN", "CULLED"] {
            if let Some(passes) = by_status.get(name) {
                let _ = writeln!(s, "      {name:<11} {}", passes.join(", "));
            }
        }
        let _ = writeln!(
            s,
            "      why: {}",
            light_space_reason(
                report,
                built_now,
                shadowed.config.static_light,
                shadowed.config.dynamic_geometry
            )
        );
        let resources: Vec<String> = report
            .allocated_resources()
            .map(|(resource, bytes)| format!("{} {}", resource.name(), size(bytes)))
            .collect();
        let _ = writeln!(
            s,
            "      memory {}: {}",
            size(own_bytes(report)),
            resources.join(", ")
        );
        let _ = writeln!(s, "      cost {}", describe_cost(report));
    }
    if let Some((prims, scratch)) = shared_bytes(frame) {
        let _ = writeln!(
            s,
            "  shared by the lights: prim buffer {}, pass scratch {} (primitive-map builds, antialiased ray traces)",
            size(prims),
            size(scratch)
        );
    }
    s
}

/// Bytes a light's report holds of its own (the shared prim buffer aside).
fn own_bytes(report: &FrameReport) -> u64 {
    report.allocated_resources().map(|(_, bytes)| bytes).sum()
}

/// Bytes the lights of `frame` share: the prim buffer and the passes' scratch (the primitive maps' build,
/// the antialiased lights' ray-trace visibility; none without a prim buffer).
fn shared_bytes(frame: &LightsFrame) -> Option<(u64, u64)> {
    let prims = frame
        .lights
        .iter()
        .map(|r| r.prim_buffer_bytes)
        .find(|&bytes| bytes > 0)?;
    let scratch = frame.lights.iter().map(|r| r.map_scratch_bytes).max();
    Some((prims, scratch.unwrap_or(0)))
}

/// GPU ms of every pass of every light of `frame`.
fn frame_gpu_ms(frame: &LightsFrame) -> f64 {
    frame.lights.iter().map(|l| gpu_ms(l).0).sum()
}

/// Median of `v` (0 when empty).
pub fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The frames rendered, summed over the lights: GPU ms a frame (the median over the frames after the
/// first, and the slowest), the per-pass split (medians of each pass's sum over the lights), and the
/// memory the lights hold, their own and shared, as the last frame reports it. Empty without a light.
pub fn describe_frames(frames: &[LightsFrame]) -> String {
    let Some(last) = frames.last().filter(|f| !f.lights.is_empty()) else {
        return String::new();
    };
    let steady = if frames.len() > 1 {
        &frames[1..]
    } else {
        frames
    };
    let totals: Vec<f64> = frames.iter().map(frame_gpu_ms).collect();
    let slowest = totals.iter().copied().fold(0.0, f64::max);
    let steady_totals = totals[frames.len() - steady.len()..].to_vec();
    let mut per_pass: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for f in steady {
        let mut sums: BTreeMap<String, f64> = BTreeMap::new();
        for l in &f.lights {
            for (name, ms) in gpu_ms(l).1 {
                *sums.entry(name).or_default() += ms;
            }
        }
        for (name, ms) in sums {
            per_pass.entry(name).or_default().push(ms);
        }
    }
    let passes: Vec<String> = per_pass
        .into_iter()
        .map(|(name, v)| format!("{name} {:.3}", median(v)))
        .collect();
    let n = last.lights.len();
    let own: u64 = last.lights.iter().map(own_bytes).sum();
    let mut s = String::new();
    let _ = writeln!(
        s,
        "all {n} lights: GPU {:.3} ms a frame (median over {} frames after the first; slowest {slowest:.3}), \
         per pass: {}",
        median(steady_totals),
        steady.len(),
        passes.join(", ")
    );
    let _ = write!(
        s,
        "  memory: the lights' own {} ({} a light)",
        size(own),
        size(own / n as u64)
    );
    if let Some((prims, scratch)) = shared_bytes(last) {
        let _ = write!(
            s,
            ", shared {} (prim buffer {}, pass scratch {})",
            size(prims + scratch),
            size(prims),
            size(scratch)
        );
    }
    s.push('\n');
    s
}

#[derive(Serialize)]
struct LightJson {
    name: String,
    decision: String,
    frusta: Vec<String>,
    visibility_png: String,
    visibility_exr: String,
}

#[derive(Serialize)]
struct LightReportJson {
    scene_light: String,
    mode: &'static str,
    light_builds: u32,
    frusta_recorded: u32,
    frusta_culled: u32,
    decision: String,
    pass_status: BTreeMap<&'static str, &'static str>,
    resource_bytes: BTreeMap<&'static str, u64>,
    gpu_ms: f64,
    pass_ms: BTreeMap<String, f64>,
    lists: ListsJson,
}

/// A light's primitive-map statistics ([`MapStats`]) in `scene_report.json`.
#[derive(Serialize)]
struct ListsJson {
    receiver_pixels: u32,
    triangles_binned: u32,
    entries: u32,
    capacity: u32,
    mean_list: f64,
    longest_list: u32,
    texels_past_capacity: u32,
}

impl From<&MapStats> for ListsJson {
    fn from(s: &MapStats) -> Self {
        Self {
            receiver_pixels: s.receiver_pixels,
            triangles_binned: s.triangles_binned,
            entries: s.entries,
            capacity: s.entry_capacity,
            mean_list: s.mean_list(),
            longest_list: s.longest_list,
            texels_past_capacity: s.texels_past_capacity,
        }
    }
}

#[derive(Serialize)]
struct FrameReportJson {
    frame_index: u64,
    lights: Vec<LightReportJson>,
}

/// The camera of the frames in `scene_report.json`.
#[derive(Serialize)]
struct CameraJson {
    position: [f32; 3],
    target: [f32; 3],
    fov_y_radians: f32,
}

#[derive(Serialize)]
struct SceneJson {
    scene: String,
    width: u32,
    height: u32,
    camera: CameraJson,
    dynamic_geometry: bool,
    plugin_lights: usize,
    lights: Vec<LightJson>,
    frames: Vec<FrameReportJson>,
}

/// A file name part of `name`: letters, digits, `_` and `-` kept, anything else `_`.
fn file_part(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The file names (PNG, EXR) of light `index`'s visibility.
pub fn visibility_file_names(index: usize, name: &str) -> (String, String) {
    let stem = format!("visibility_{index}_{}", file_part(name));
    (format!("{stem}.png"), format!("{stem}.exr"))
}

/// Renders `frames` frames of `planned` (from `source`, for messages) as its plan says, prints the plan
/// and each frame's per-light report, and writes into `out`: `shaded.png` and `shaded.exr` (linear
/// radiance), each light's visibility (`visibility_<i>_<name>.png` and `.exr`) and `scene_report.json`.
pub fn render_scene_to_folder(
    device: &Device,
    source: &Path,
    planned: &PlannedScene,
    frames: u32,
    out: &Path,
) -> Result<()> {
    let PlannedScene {
        file,
        camera,
        settings,
        plan,
    } = planned;
    let (width, height) = (settings.width, settings.height);
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    println!("{}", demo_engine::device::device_banner(device));
    println!(
        "scene {}: {} triangles, {}x{} px",
        source.display(),
        file.scene.triangle_count(),
        width,
        height
    );
    print!("{}", plan.describe());
    // Steps: the renderer's creation, each frame, the outputs.
    let bar = crate::progress(u64::from(frames) + 2, "render");
    bar.set_message("creating the renderer");
    let mut renderer =
        SceneRenderer::new(device, file, width, height).context("creating the renderer")?;
    // As an engine that gives its output storage usage: each light writes its layer, no copy.
    renderer.write_outputs_directly();
    bar.inc(1);
    let mut reports: Vec<LightsFrame> = Vec::new();
    for index in 1..=frames {
        bar.set_message(format!("frame {index} of {frames}"));
        let frame = renderer.render(device, camera, plan).context("rendering")?;
        bar.inc(1);
        // Every light's passes, memory and cost for the first frame (what was built) and the last (what
        // later frames kept); one line for the frames between.
        let text = if index == 1 || index == frames {
            describe_frame(plan, &frame, reports.last())
        } else {
            format!(
                "frame {}: {} lights, GPU {:.3} ms\n",
                frame.frame_index,
                frame.lights.len(),
                frame_gpu_ms(&frame)
            )
        };
        bar.suspend(|| print!("{text}"));
        reports.push(frame);
    }
    bar.suspend(|| print!("{}", describe_frames(&reports)));
    bar.set_message("reading back and writing the outputs");
    let images = renderer.read_back(device, plan).context("reading back")?;
    let (w, h) = (width, height);
    let radiance = shade(
        &file.lights,
        &images.visibility,
        &images.gbuffer.position,
        &images.gbuffer.normal,
        SKY_RADIANCE,
    );
    write_png(&out.join("shaded.png"), w, h, &tone_map(&radiance))?;
    let rgba: Vec<[f32; 4]> = radiance.iter().map(|c| c.extend(1.0).to_array()).collect();
    write_exr_rgba(&out.join("shaded.exr"), w, h, &rgba)?;
    let mut lights_json = Vec::new();
    for (i, (light, visibility)) in plan.lights.iter().zip(&images.visibility).enumerate() {
        let (png_name, exr_name) = visibility_file_names(i, &light.light.name);
        let grey: Vec<[u8; 4]> = visibility
            .iter()
            .map(|&v| {
                let g = (v.clamp(0.0, 1.0) * 255.0).round() as u8;
                [g, g, g, 255]
            })
            .collect();
        write_png(&out.join(&png_name), w, h, &grey)?;
        write_exr_scalar(&out.join(&exr_name), w, h, visibility)?;
        lights_json.push(LightJson {
            name: light.light.name.clone(),
            decision: light.describe_decision(),
            frusta: light
                .shadowed()
                .map(|s| s.frusta.iter().map(|&f| f.to_owned()).collect())
                .unwrap_or_default(),
            visibility_png: png_name,
            visibility_exr: exr_name,
        });
    }
    let plugin_lights = plan.plugin_lights();
    let frames_json = reports
        .iter()
        .map(|frame| FrameReportJson {
            frame_index: frame.frame_index,
            lights: frame
                .lights
                .iter()
                .zip(&plugin_lights)
                .map(|(report, pl)| LightReportJson {
                    scene_light: plan.lights[pl.scene_light].light.name.clone(),
                    mode: pl.shadowed.resolved_config().mode.name(),
                    light_builds: report.light_builds,
                    frusta_recorded: report.frusta,
                    frusta_culled: report.frusta_culled,
                    decision: report.decision_reason.clone(),
                    pass_status: hrts::PassMask::ALL
                        .iter()
                        .map(|p| (p.name(), report.status(p).name()))
                        .collect(),
                    resource_bytes: resource_bytes(report).collect(),
                    gpu_ms: gpu_ms(report).0,
                    pass_ms: gpu_ms(report).1,
                    lists: ListsJson::from(&report.stats),
                })
                .collect(),
        })
        .collect();
    let json = SceneJson {
        scene: source.display().to_string(),
        width: w,
        height: h,
        camera: CameraJson {
            position: camera.position.to_array(),
            target: camera.target.to_array(),
            fov_y_radians: camera.fov_y_radians,
        },
        dynamic_geometry: plan.dynamic_geometry,
        plugin_lights: plugin_lights.len(),
        lights: lights_json,
        frames: frames_json,
    };
    let text = serde_json::to_string_pretty(&json)?;
    std::fs::write(out.join("scene_report.json"), text)
        .with_context(|| format!("writing {}/scene_report.json", out.display()))?;
    bar.inc(1);
    bar.finish_and_clear();
    println!(
        "outputs in {}: shaded.png, shaded.exr, scene_report.json, visibility_<light>_<name>.png/.exr",
        out.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_names_are_safe() {
        assert_eq!(
            visibility_file_names(3, "cart lamp/1"),
            (
                "visibility_3_cart_lamp_1.png".to_owned(),
                "visibility_3_cart_lamp_1.exr".to_owned()
            )
        );
    }
}
