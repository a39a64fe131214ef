//! `hrts_lab hardcases`: runs every [hard case](scene::hard_cases) on a device and measures it.
//!
//! Per case: the frame is rendered once (G-buffer, primitive map, ray trace) and read back; visibility is
//! compared with the exact f64 reference (pixels whose exact shadow ray passes within a tolerance of an
//! edge are counted as near-edge and not compared), the primitive map with exact conservative binning,
//! and the case's analytic [`Check`]s are decided from the GPU's receiver positions:
//!
//! - **leaks**: lit receivers whose shadow ray passes through a blocker shrunk by [`MARGIN_PIXELS`] pixel
//!   footprints;
//! - **acne**: shadowed light-facing receivers where nothing lies between them and the light;
//! - **contact gap**: the largest screen distance between a lit receiver in a contact shadow and the
//!   footprint edge it should start at (peter-panning), which must stay below one pixel;
//! - **differing pixels** from the untransformed scene, for translated and scaled copies;
//! - the guard words past the entry capacity, which must hold [`GUARD_VALUE`] everywhere.
//!
//! The integration test `tests/tests/hard_cases.rs` calls [`run_cases`] too, so the table and the tests
//! cannot drift apart.

use crate::accuracy::{compare_map, compare_visibility, fitted_light_matrix};
use crate::frames::{PluginFrames, ViewInputs};
use anyhow::{anyhow, bail, Context, Result};
use demo_engine::gbuffer::GBufferLayout;
use demo_engine::plugin::PluginRenderer;
use demo_engine::{FrameImages, View};
use glam::{DVec3, Mat4};
use host_demo::output::write_png;
use hrts::passes_bridge;
use passes::{
    BinningRequest, FaceMode, FrameInputs, Light, PrimitiveMapConfig, DEFAULT_ENTRY_BUDGET,
    GUARD_VALUE, GUARD_WORDS,
};
use reference::{FaceSelection, RefScene};
use rhi::Device;
use scene::hard_cases::{Check, Expectation, HardCase, Overflow};
use scene::{DirectionalLight, Scene};
use std::collections::HashMap;
use std::path::Path;
use std::time::Instant;

mod cli;
mod probe;

pub use cli::{run_cli, table, HardcasesArgs};
use probe::Probe;
pub use probe::MARGIN_PIXELS;

/// What one case measured.
#[derive(Debug, Clone, Default)]
pub struct Outcome {
    /// Case name.
    pub name: &'static str,
    /// Rendered pixels.
    pub pixels: usize,
    /// Pixels near an edge within the reference's tolerance (counted, not compared).
    pub near_edge: usize,
    /// Visibility disagreements with the reference outside near-edge pixels.
    pub mismatches: usize,
    /// Blocker-distance disagreements with the reference.
    pub blocker_mismatches: usize,
    /// First disagreeing pixels `(x, y, exact class, GPU value)`.
    pub examples: Vec<(u32, u32, &'static str, f32)>,
    /// Whether blocker distances are comparable with the reference: not with front faces only, where the
    /// distance is to the light-facing side of the blocker (where the ray leaves it), not its nearest side.
    pub blocker_distance_compared: bool,
    /// Receivers judged by the analytic checks: `[certainly shadowed, certainly lit, in a contact shadow]`.
    pub judged: [usize; 3],
    /// Analytic checks that judged no pixel at all (the case does not test what it claims).
    pub vacuous_checks: Vec<String>,
    /// Lit receivers that are certainly shadowed ([`Check::Shadowed`]).
    pub leaks: usize,
    /// Shadowed light-facing receivers that are certainly lit ([`Check::Lit`]).
    pub acne: usize,
    /// Largest screen distance in pixels between a lit receiver of a contact shadow and its footprint
    /// edge ([`Check::Contact`]); 0 when every such receiver is shadowed.
    pub contact_gap_pixels: Option<f64>,
    /// Pixels whose visibility differs from the base case ([`Check::SameAs`]).
    pub differing_pixels: Option<Differing>,
    /// NaN or Inf in visibility or blocker distance.
    pub non_finite: usize,
    /// Texels whose list did not fit the entry capacity (traced exhaustively).
    pub texels_past_capacity: u32,
    /// Longest list.
    pub longest_list: u32,
    /// What the case expects of overflow.
    pub overflow: Option<Overflow>,
    /// Required triangles missing from texel lists.
    pub map_missing: usize,
    /// Texel-list entries that are out of range, duplicated, or do not touch the texel.
    pub map_garbage: usize,
    /// Guard-layer texels written (with a guard layer).
    pub guard_written: Option<usize>,
    /// Vulkan validation errors raised while running the case.
    pub validation_errors: u32,
    /// The load error of a case that must be rejected.
    pub rejected: Option<String>,
    /// What stopped the case, if anything did.
    pub error: Option<String>,
    /// Raster path used.
    pub binning_path: &'static str,
    /// Wall-clock seconds (render, read-back and all comparisons).
    pub seconds: f64,
}

/// Pixels whose visibility differs from a base case's.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Differing {
    /// Pixels that differ.
    pub total: usize,
    /// Pixels that differ although neither reference puts them near an edge: the exact answer itself
    /// changed with the f32 rounding of the transformed input (both images match their references there).
    pub outside_near_edge: usize,
    /// Largest `total` allowed.
    pub bound: usize,
}

impl Outcome {
    /// Every violated expectation, in words; empty when the case passes.
    pub fn failures(&self) -> Vec<String> {
        let mut f: Vec<String> = self.error.iter().cloned().collect();
        let blocker_mismatches = if self.blocker_distance_compared {
            self.blocker_mismatches
        } else {
            0
        };
        let differing = self.differing_pixels.unwrap_or_default();
        for (n, what) in [
            (self.mismatches, "mismatches"),
            (blocker_mismatches, "blocker-distance mismatches"),
            (self.leaks, "leaks"),
            (self.acne, "acne pixels"),
            (self.non_finite, "NaN/Inf pixels"),
            (self.map_missing, "missing map entries"),
            (self.map_garbage, "garbage map entries"),
            (self.guard_written.unwrap_or(0), "guard texels written"),
            (self.validation_errors as usize, "validation errors"),
        ] {
            if n > 0 {
                f.push(format!("{n} {what}"));
            }
        }
        if self.mismatches + blocker_mismatches > 0 {
            let shown: Vec<String> = self
                .examples
                .iter()
                .take(3)
                .map(|(x, y, what, value)| format!("({x}, {y}) exact {what}, GPU {value}"))
                .collect();
            f.push(format!("e.g. {}", shown.join(", ")));
        }
        f.extend(
            self.vacuous_checks
                .iter()
                .map(|c| format!("{c} judged no pixel")),
        );
        if let Some(gap) = self.contact_gap_pixels.filter(|&g| g >= 1.0) {
            f.push(format!("contact gap {gap:.2} px >= 1 px"));
        }
        if differing.total > differing.bound {
            f.push(format!(
                "{} pixels differ from the base (bound {})",
                differing.total, differing.bound
            ));
        }
        match self.overflow {
            Some(Overflow::Forbidden) if self.texels_past_capacity > 0 => {
                f.push("texels past the entry capacity in the second frame".into())
            }
            Some(Overflow::Required) if self.texels_past_capacity == 0 => {
                f.push("no texel past the entry capacity".into())
            }
            _ => {}
        }
        f
    }

    /// Whether every expectation holds.
    pub fn passed(&self) -> bool {
        self.failures().is_empty()
    }

    /// The result column: `pass`, `rejected: <message>` or `FAIL: <reasons>`.
    pub fn result(&self) -> String {
        let failures = self.failures();
        if !failures.is_empty() {
            format!("FAIL: {}", failures.join("; "))
        } else if let Some(message) = &self.rejected {
            format!("rejected: {message}")
        } else {
            "pass".into()
        }
    }

    /// The family-specific measure column.
    pub fn measure(&self) -> String {
        let mut m = Vec::new();
        let [shadowed, lit, contact] = self.judged;
        for (n, what) in [
            (shadowed, "certainly shadowed"),
            (lit, "certainly lit"),
            (contact, "in contact shadows"),
        ] {
            if n > 0 {
                m.push(format!("{n} px {what}"));
            }
        }
        if !self.blocker_distance_compared && self.blocker_mismatches > 0 {
            m.push(format!(
                "blocker distance to the far side on {} px (front faces only)",
                self.blocker_mismatches
            ));
        }
        if let Some(gap) = self.contact_gap_pixels {
            m.push(format!("contact gap {gap:.2} px"));
        }
        if let Some(d) = self.differing_pixels {
            m.push(format!(
                "{} px differ from the base (bound {}; exact answer changed on {})",
                d.total, d.bound, d.outside_near_edge
            ));
        }
        if let Some(written) = self.guard_written {
            m.push(if written == 0 {
                "guard intact".into()
            } else {
                format!("guard: {written} written")
            });
        }
        if self.rejected.is_none() && self.error.is_none() {
            m.push(format!("longest list {}", self.longest_list));
        }
        m.join(", ")
    }
}

/// Runs `cases` in order on `device`, the plugin reading a G-buffer of `layout`; a case whose
/// [`Check::SameAs`] names an earlier case is compared with that case's image. With `previews`, writes a
/// shaded PNG per case there (analytic failures red).
pub fn run_cases(
    device: &Device,
    cases: &[HardCase],
    layout: GBufferLayout,
    previews: Option<&Path>,
) -> Vec<Outcome> {
    let mut bases = HashMap::new();
    let bar = host_demo::progress(cases.len() as u64, "hard cases");
    let outcomes = cases
        .iter()
        .map(|c| {
            bar.set_message(c.name);
            let o = run_case(device, c, layout, &mut bases, previews);
            bar.inc(1);
            o
        })
        .collect();
    bar.finish_and_clear();
    outcomes
}

/// Visibility images and near-edge masks of the cases run so far, by name.
type Bases = HashMap<&'static str, (Vec<f32>, Vec<bool>)>;

fn run_case(
    device: &Device,
    case: &HardCase,
    layout: GBufferLayout,
    bases: &mut Bases,
    previews: Option<&Path>,
) -> Outcome {
    let start = Instant::now();
    let errors_before = device.validation().errors();
    let mut o = Outcome {
        name: case.name,
        ..Outcome::default()
    };
    match (&case.scene, &case.expectation) {
        (Err(e), Expectation::RejectedAtLoad) => o.rejected = Some(e.to_string()),
        (Ok(_), Expectation::RejectedAtLoad) => {
            o.error = Some("non-finite input was accepted".into())
        }
        (Err(e), Expectation::Renders(_)) => o.error = Some(format!("loading failed: {e}")),
        (Ok(scene), Expectation::Renders(checks)) => {
            if let Err(e) = measure(device, case, scene, checks, layout, bases, previews, &mut o) {
                o.error = Some(format!("{e:#}"));
            }
        }
    }
    o.validation_errors = device.validation().errors().saturating_sub(errors_before);
    o.seconds = start.elapsed().as_secs_f64();
    o
}

#[allow(clippy::too_many_arguments)]
fn measure(
    device: &Device,
    case: &HardCase,
    scene: &Scene,
    checks: &[Check],
    layout: GBufferLayout,
    bases: &mut Bases,
    previews: Option<&Path>,
    o: &mut Outcome,
) -> Result<()> {
    let frame = case.frame;
    let mut view = View::framed(scene.clone(), frame.width, frame.height);
    view.light = DirectionalLight::new(case.light_direction)
        .ok_or_else(|| anyhow!("unusable light direction {}", case.light_direction))?;
    if let Some(camera) = case.camera {
        view.camera = camera;
    }
    let mut inputs = view.frame_inputs();
    if let Some(m) = case.light_view_proj {
        set_light_matrix(&mut inputs, m);
    }
    let config = PrimitiveMapConfig {
        size: case.map.size,
        faces: if case.map.front_faces_only {
            FaceMode::FrontOnly
        } else {
            FaceMode::Both
        },
        binning: BinningRequest::Auto,
        entry_budget: case
            .map
            .entry_budget
            .map_or(DEFAULT_ENTRY_BUDGET, |entries| {
                (u64::from(entries)
                    + if case.map.guard {
                        u64::from(GUARD_WORDS)
                    } else {
                        0
                    })
                    * 4
            }),
        guard: case.map.guard,
        receiver_culling: case.map.receiver_culling,
        ..PrimitiveMapConfig::default()
    };
    // A case meant to pass its entry budget builds every list, however long, so that it does.
    let config = match case.map.overflow {
        Overflow::Required => PrimitiveMapConfig {
            list_limit: u32::MAX,
            bin_budget: f32::INFINITY,
            ..config
        },
        _ => config,
    };
    let mut renderer = PluginRenderer::with_layout(
        device,
        &view,
        passes_bridge::config(&config.into())?,
        layout,
    )
    .context("creating the renderer")?;
    let mut report = renderer.render(device, &inputs).context("rendering")?;
    if report.stats.texels_past_capacity > 0 && case.map.overflow == Overflow::Forbidden {
        // The lists grew to what this frame needed: the next frame, as an engine's would, fits.
        report = renderer.render(device, &inputs).context("rendering")?;
    }
    let images = renderer.read_back(device, true).context("reading back")?;
    o.binning_path = report.binning_path.name();
    o.texels_past_capacity = report.stats.texels_past_capacity;
    o.longest_list = report.stats.longest_list;
    o.overflow = Some(case.map.overflow);

    let rs = RefScene::new(&view.scene);
    let v = compare_visibility(&rs, &view, &images);
    let near_edge_mask = v.near_edge_mask;
    o.pixels = v.pixels;
    o.near_edge = v.near_edge;
    o.mismatches = v.mismatches;
    o.blocker_mismatches = v.blocker_mismatches;
    o.blocker_distance_compared = !case.map.front_faces_only;
    o.examples = v.examples;
    o.non_finite = v.non_finite;
    let faces = match config.faces {
        FaceMode::FrontOnly => FaceSelection::FrontOnly,
        FaceMode::Both => FaceSelection::Both,
    };
    let light = fitted_light_matrix(report.map_to_texels, renderer.scene().origin(), config.size);
    let m = compare_map(
        &rs,
        light,
        inputs.light.direction(),
        &config,
        &images,
        faces,
    );
    o.map_missing = m.missing;
    o.map_garbage = m.garbage;
    if config.guard {
        let capacity = images
            .list_entries
            .len()
            .saturating_sub(GUARD_WORDS as usize);
        o.guard_written = Some(
            images.list_entries[capacity..]
                .iter()
                .filter(|&&i| i != GUARD_VALUE)
                .count(),
        );
    }

    let probe = Probe::new(&view, &inputs, &images);
    let mut flagged = vec![false; images.visibility.len()];
    for (k, check) in checks.iter().enumerate() {
        let judged = match check {
            Check::Shadowed(solid) => {
                let (judged, leaks) = probe.leaks(solid, &mut flagged);
                o.leaks += leaks;
                o.judged[0] += judged;
                Some(judged)
            }
            Check::Lit(region) => {
                let (judged, acne) = probe.acne(region, &mut flagged);
                o.acne += acne;
                o.judged[1] += judged;
                Some(judged)
            }
            Check::Contact(b) => {
                let (judged, gap) = probe.contact_gap(b, &mut flagged);
                o.contact_gap_pixels = Some(o.contact_gap_pixels.unwrap_or(0.0).max(gap));
                o.judged[2] += judged;
                Some(judged)
            }
            Check::SameAs {
                base,
                max_differing_pixels,
            } => {
                let (base_image, base_near_edge) = bases
                    .get(base)
                    .ok_or_else(|| anyhow!("base case \"{base}\" was not run before"))?;
                if base_image.len() != images.visibility.len() {
                    bail!("base case \"{base}\" has a different frame size");
                }
                let mut d = Differing {
                    bound: *max_differing_pixels,
                    ..Differing::default()
                };
                for (i, (a, b)) in base_image.iter().zip(&images.visibility).enumerate() {
                    if a != b {
                        d.total += 1;
                        if !base_near_edge[i] && !near_edge_mask[i] {
                            d.outside_near_edge += 1;
                        }
                    }
                }
                o.differing_pixels = Some(d);
                None
            }
        };
        if judged == Some(0) {
            o.vacuous_checks
                .push(format!("check {} ({})", k + 1, check_kind(check)));
        }
    }
    if let Some(folder) = previews {
        std::fs::create_dir_all(folder)
            .with_context(|| format!("creating {}", folder.display()))?;
        write_png(
            &folder.join(format!("{}.png", slug(case.name))),
            frame.width,
            frame.height,
            &preview(&images, probe.to_light, &flagged),
        )?;
    }
    bases.insert(case.name, (images.visibility, near_edge_mask));
    Ok(())
}

/// Replaces the light matrix of `inputs` (the direction stays).
fn set_light_matrix(inputs: &mut FrameInputs, view_proj: Mat4) {
    inputs.light = Light::Directional {
        direction: inputs.light.direction(),
        view_proj,
    };
}

/// Short name of a check's kind.
fn check_kind(check: &Check) -> &'static str {
    match check {
        Check::Shadowed(_) => "shadowed",
        Check::Lit(_) => "lit",
        Check::Contact(_) => "contact",
        Check::SameAs { .. } => "same as",
    }
}

/// Preview: lit receivers light (brighter facing the light), shadowed ones dark, background blue, pixels
/// failing an analytic check red.
fn preview(images: &FrameImages, to_light: DVec3, flagged: &[bool]) -> Vec<[u8; 4]> {
    let pixel = |i: usize| {
        let n = images.normal[i];
        if flagged[i] {
            return [255, 0, 0, 255];
        }
        if n[3] == 0.0 {
            return [150, 180, 215, 255];
        }
        let facing = DVec3::new(n[0].into(), n[1].into(), n[2].into())
            .dot(to_light)
            .clamp(0.0, 1.0);
        let g = if images.visibility[i] > 0.5 {
            170.0 + 85.0 * facing
        } else {
            45.0 + 35.0 * facing
        };
        let g = g as u8;
        [g, g, g, 255]
    };
    (0..images.normal.len()).map(pixel).collect()
}

/// `name` in lower case with every run of other characters than ASCII letters and digits as one `-`.
fn slug(name: &str) -> String {
    let mut s = String::new();
    for c in name.chars() {
        if c.is_ascii_alphanumeric() {
            s.push(c.to_ascii_lowercase());
        } else if !s.ends_with('-') {
            s.push('-');
        }
    }
    s.trim_matches('-').to_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_layout() {
        let pass = Outcome {
            name: "a | b",
            pixels: 10,
            binning_path: "software",
            ..Outcome::default()
        };
        let rejected = Outcome {
            name: "nan",
            rejected: Some("x.obj: vertex 1 has a non-finite coordinate (NaN)".into()),
            ..Outcome::default()
        };
        let failed = Outcome {
            name: "leaky",
            leaks: 3,
            ..Outcome::default()
        };
        assert!(pass.passed() && rejected.passed() && !failed.passed());
        let md = table(&[pass.clone(), rejected, failed], true);
        let lines: Vec<&str> = md.lines().collect();
        assert_eq!(lines.len(), 5);
        assert!(lines[2].starts_with("| a \\| b | 10 |"), "{}", lines[2]);
        assert!(lines[3].contains("| rejected: x.obj"), "{}", lines[3]);
        assert!(lines[4].ends_with("FAIL: 3 leaks |"), "{}", lines[4]);
        let text = table(&[pass], false);
        assert!(text.lines().all(|l| !l.ends_with(' ')));
        assert_eq!(slug("fan disc (96 triangles)"), "fan-disc-96-triangles");
    }
}
