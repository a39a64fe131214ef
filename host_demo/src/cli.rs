//! What the command lines of `host_demo` and `hrts_lab` share: how a program runs, the camera options,
//! negative numbers as people type them (`--camera-pos -5,2,3`, not only `--camera-pos=-5,2,3`), and
//! the check of it.

use crate::parse_vec3;
use anyhow::Result;
use glam::Vec3;
use scene::{Aabb, Camera};
use std::any::TypeId;
use std::process::ExitCode;

/// Runs a program: logging from `RUST_LOG` (warnings by default), its command line `command()` parsed
/// into `C` (clap's message and exit code on bad arguments), then `run`, whose error is printed as
/// `error: ...` with exit code 1.
pub fn main_of<C: clap::FromArgMatches>(
    command: impl Fn() -> clap::Command,
    run: impl FnOnce(&C) -> Result<()>,
) -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = C::from_arg_matches(&command().get_matches())
        .unwrap_or_else(|e| e.format(&mut command()).exit());
    match run(&cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// The size of the frame rendered.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct FrameSizeArgs {
    /// Frame width in pixels.
    #[arg(long, default_value_t = 1280, value_parser = clap::value_parser!(u32).range(1..=i64::from(crate::limits::FRAME_SIDE)))]
    pub width: u32,
    /// Frame height in pixels.
    #[arg(long, default_value_t = 720, value_parser = clap::value_parser!(u32).range(1..=i64::from(crate::limits::FRAME_SIDE)))]
    pub height: u32,
}

/// Where the camera is, when not framed automatically (or, with `--scene`, taken from the file).
#[derive(Debug, Clone, clap::Args)]
pub struct CameraArgs {
    /// Camera position "x,y,z" (default: the scene file's camera, else framed automatically: from
    /// outside, or inside a closed model, in a corner at eye height looking across the room).
    #[arg(long, value_parser = parse_vec3)]
    pub camera_pos: Option<Vec3>,
    /// Camera target "x,y,z" (default: the centre of the scene's bounds where --camera-pos is given, else
    /// the scene file's camera's, else the framed camera's).
    #[arg(long, value_parser = parse_vec3)]
    pub camera_target: Option<Vec3>,
}

impl CameraArgs {
    /// `camera` moved as these options say ([`Camera::placed`]).
    pub fn apply(&self, camera: Camera, bounds: &Aabb) -> Result<Camera> {
        Ok(camera.placed(bounds, self.camera_pos, self.camera_target)?)
    }
}

/// `command` and its subcommands with negative values allowed on the options of numbers: an option of
/// one number takes a negative number (`allow_negative_numbers`); a vector or a list of numbers, whose
/// value is no number as a whole, takes a value that begins with a hyphen (`allow_hyphen_values`), so
/// that such an option followed by another flag takes the flag as its value and fails to parse it.
pub fn negative_numbers(command: clap::Command) -> clap::Command {
    command
        .mut_args(|arg| {
            let value = arg.get_value_parser().type_id();
            let number = [
                TypeId::of::<u32>(),
                TypeId::of::<u64>(),
                TypeId::of::<i32>(),
                TypeId::of::<i64>(),
                TypeId::of::<usize>(),
                TypeId::of::<f32>(),
                TypeId::of::<f64>(),
            ]
            .into_iter()
            .any(|t| value == t);
            if value == TypeId::of::<Vec3>() || (number && arg.get_value_delimiter().is_some()) {
                arg.allow_hyphen_values(true)
            } else if number {
                arg.allow_negative_numbers(true)
            } else {
                arg
            }
        })
        .mut_subcommands(negative_numbers)
}

/// Checks that every option of numbers of every subcommand of `command()` (a command built with
/// [`negative_numbers`]) takes a negative value as a separate argument (`--flag -1`, a vector
/// `-1,-2,-3`, a list `-1,2`): it is parsed as the option's value (and then accepted, or refused by the
/// option's own check), never as an unknown argument. Returns the options checked ("render
/// --camera-pos", ...), or the first that failed.
pub fn check_negative_numbers(
    command: impl Fn() -> clap::Command,
) -> std::result::Result<Vec<String>, String> {
    use clap::error::ErrorKind;
    let root = command();
    let mut checked = Vec::new();
    for sub in root.get_subcommands() {
        for arg in sub.get_arguments() {
            let Some(long) = arg.get_long() else { continue };
            let value = if !arg.is_allow_hyphen_values_set() {
                if !arg.is_allow_negative_numbers_set() {
                    continue;
                }
                "-1"
            } else if arg.get_value_parser().type_id() == TypeId::of::<Vec3>() {
                "-1,-2,-3"
            } else {
                "-1,2"
            };
            let flag = format!("--{long}");
            let case = format!("{} {flag} {value}", sub.get_name());
            match command().try_get_matches_from([root.get_name(), sub.get_name(), &flag, value]) {
                Ok(m) => {
                    let raw: Vec<_> = m
                        .subcommand_matches(sub.get_name())
                        .and_then(|m| m.get_raw(arg.get_id().as_str()))
                        .map(|r| r.map(|v| v.to_string_lossy().into_owned()).collect())
                        .unwrap_or_default();
                    if raw.join(",") != value {
                        return Err(format!("{case}: parsed as {raw:?}"));
                    }
                }
                Err(e)
                    if matches!(
                        e.kind(),
                        ErrorKind::ValueValidation
                            | ErrorKind::MissingRequiredArgument
                            | ErrorKind::InvalidValue
                    ) && !e.to_string().contains("unexpected argument") => {}
                Err(e) => return Err(format!("{case}: {e}")),
            }
            checked.push(format!("{} {flag}", sub.get_name()));
        }
    }
    Ok(checked)
}
