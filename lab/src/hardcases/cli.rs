//! The `hrts_lab hardcases` subcommand: its arguments, the run, and the outcome table.

use super::{run_cases, Outcome};
use anyhow::{bail, Result};
use demo_engine::gbuffer::GBufferLayout;
use scene::hard_cases::{Family, HardCase};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `hrts_lab hardcases`.
#[derive(Debug, clap::Args)]
pub struct HardcasesArgs {
    /// Print the table as Markdown (for the README).
    #[arg(long)]
    pub markdown: bool,
    /// Run only these families (repeatable): shared-edges, grazing, contact, scale, small-triangles,
    /// texel-boundaries, frustum-border, coplanar, thin-geometry, models, non-finite, overflow.
    #[arg(long, value_parser = parse_family)]
    pub family: Vec<Family>,
    /// The models folder (default: `HRTS_MODELS`, else `../shared/models` beside the checkout).
    #[arg(long)]
    pub models: Option<PathBuf>,
    /// Write a shaded preview PNG of every case into this folder (pixels failing an analytic check in red).
    #[arg(long)]
    pub previews: Option<PathBuf>,
    /// The normal target the plugin reads: rgba32f-world (the default), rgba16f-world, rgb10a2-view,
    /// rgba8-world, oct-rg16snorm-view, oct-rg16unorm-world, oct-rg16f-view, oct-rgb10a2-world.
    #[arg(long, default_value = "rgba32f-world", value_parser = GBufferLayout::analysis_with)]
    pub normals: GBufferLayout,
}

fn parse_family(s: &str) -> Result<Family, String> {
    Family::from_name(s).ok_or_else(|| {
        let names: Vec<&str> = Family::ALL.iter().map(|f| f.name()).collect();
        format!(
            "unknown family '{s}' (expected one of {})",
            names.join(", ")
        )
    })
}

/// Runs the subcommand: creates the device (`device_filter`, `validation` as for `render`), runs the
/// cases, prints the table, and fails if any case failed.
pub fn run_cli(
    device_filter: Option<String>,
    validation: bool,
    args: &HardcasesArgs,
) -> Result<()> {
    let validation = validation || rhi::DeviceDesc::from_env().validation;
    let device = demo_engine::open_device(device_filter, validation)?;
    let families = if args.family.is_empty() {
        Family::ALL.to_vec()
    } else {
        args.family.clone()
    };
    let models = match &args.models {
        Some(dir) => dir.clone(),
        None => scene::models_dir().map_err(anyhow::Error::msg)?,
    };
    let cases: Vec<HardCase> = families
        .iter()
        .flat_map(|&f| scene::hard_cases::family(f, &models))
        .collect();
    let start = Instant::now();
    let outcomes = run_cases(&device, &cases, args.normals, args.previews.as_deref());
    let caps = device.capabilities();
    let path = outcomes
        .iter()
        .map(|o| o.binning_path)
        .find(|p| !p.is_empty())
        .unwrap_or("none");
    println!(
        "Hard cases on {} ({}), {} binning, validation {}, the plugin reading {:?} normals ({:?}, {:?}): {:.1} s\n",
        caps.device_name,
        caps.driver,
        path,
        if validation { "on" } else { "off" },
        args.normals.normal_encoding,
        args.normals.normal,
        args.normals.normal_space,
        start.elapsed().as_secs_f64()
    );
    print!("{}", table(&outcomes, args.markdown));
    let failed = outcomes.iter().filter(|o| !o.passed()).count();
    if failed > 0 {
        bail!("{failed} of {} hard cases failed", outcomes.len());
    }
    println!("\nall {} hard cases pass", outcomes.len());
    Ok(())
}

/// The outcome table: plain text with aligned columns, or Markdown.
pub fn table(outcomes: &[Outcome], markdown: bool) -> String {
    const HEADER: [&str; 12] = [
        "case",
        "pixels",
        "near-edge",
        "mismatches",
        "leaks",
        "acne",
        "NaN/Inf",
        "texels past capacity",
        "map errors",
        "measure",
        "time",
        "result",
    ];
    let rows: Vec<[String; 12]> = outcomes
        .iter()
        .map(|o| {
            let rendered = o.rejected.is_none() && o.error.is_none();
            let n = |v: usize| {
                if rendered {
                    v.to_string()
                } else {
                    "-".into()
                }
            };
            [
                o.name.to_owned(),
                n(o.pixels),
                n(o.near_edge),
                n(o.mismatches),
                n(o.leaks),
                n(o.acne),
                n(o.non_finite),
                n(o.texels_past_capacity as usize),
                n(o.map_missing + o.map_garbage),
                o.measure(),
                format!("{:.1} s", o.seconds),
                o.result(),
            ]
        })
        .collect();
    let mut out = String::new();
    if markdown {
        let line = |cells: &[&str]| format!("| {} |\n", cells.join(" | "));
        out += &line(&HEADER);
        let align: Vec<&str> = HEADER
            .iter()
            .map(|h| match *h {
                "case" | "measure" | "result" => "---",
                _ => "---:",
            })
            .collect();
        out += &line(&align);
        for r in &rows {
            let cells: Vec<String> = r.iter().map(|c| c.replace('|', "\\|")).collect();
            out += &line(&cells.iter().map(String::as_str).collect::<Vec<_>>());
        }
    } else {
        let mut widths = HEADER.map(|h| h.chars().count());
        for r in &rows {
            for (w, c) in widths.iter_mut().zip(r) {
                *w = (*w).max(c.chars().count());
            }
        }
        let line = |cells: &[&str]| {
            let padded: Vec<String> = cells
                .iter()
                .zip(widths)
                .enumerate()
                .map(|(i, (c, w))| {
                    if (1..9).contains(&i) || i == 10 {
                        format!("{c:>w$}")
                    } else {
                        format!("{c:<w$}")
                    }
                })
                .collect();
            format!("{}\n", padded.join("  ").trim_end())
        };
        out += &line(&HEADER);
        for r in &rows {
            out += &line(&r.iter().map(String::as_str).collect::<Vec<_>>());
        }
    }
    out
}
