//! Where the test models live: `../shared/models` beside the checkout (see its README for sources and
//! licenses), or the folder `HRTS_MODELS` names.

use std::path::PathBuf;

/// The environment variable that points at another models folder.
pub const MODELS_ENV: &str = "HRTS_MODELS";

/// The models folder: `HRTS_MODELS` if set, else `../shared/models` beside this checkout. Fails with a
/// message saying where it looked and how to point elsewhere when the folder is missing.
pub fn models_dir() -> Result<PathBuf, String> {
    let (dir, how) = match std::env::var_os(MODELS_ENV) {
        Some(dir) => (PathBuf::from(dir), format!("{MODELS_ENV} is set")),
        None => (
            PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/models")),
            format!("the default, beside the checkout; set {MODELS_ENV} to use another folder"),
        ),
    };
    if dir.join("02_stanford_bunny_69k.obj").is_file() {
        Ok(dir)
    } else {
        Err(format!(
            "the test models are not in {} ({how}); they come from the project's shared folder \
             (shared/models, with their sources and licenses in its README)",
            dir.display()
        ))
    }
}
