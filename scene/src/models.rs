//! Where the test models live: `../shared/models` beside the checkout (see its README for sources and
//! licenses), or the folder `HRTS_MODELS` names.

use std::path::PathBuf;

/// The environment variable that points at another models folder.
pub const MODELS_ENV: &str = "HRTS_MODELS";

/// A model of the shared folder that [`models_dir`] looks for to tell it is the folder of the test models.
const PROBE: &str = "02_stanford_bunny_69k.obj";

/// The models folder without looking into it: `HRTS_MODELS` if set, else `../shared/models` beside this
/// checkout; with how it was chosen, for messages ("HRTS_MODELS is set", …).
pub fn models_folder() -> (PathBuf, String) {
    match std::env::var_os(MODELS_ENV) {
        Some(dir) => (PathBuf::from(dir), format!("{MODELS_ENV} is set")),
        None => (
            PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/models")),
            format!("the default, beside the checkout; set {MODELS_ENV} to use another folder"),
        ),
    }
}

/// The folder of the test models ([`models_folder`]). Fails with a message saying where it looked, what
/// it expected there and how to point elsewhere when the folder lacks the shared models.
pub fn models_dir() -> Result<PathBuf, String> {
    let (dir, how) = models_folder();
    if dir.join(PROBE).is_file() {
        Ok(dir)
    } else {
        Err(format!(
            "the test models are not in {} ({how}): it has no {PROBE}. They come from the project's \
             shared folder (shared/models, with their sources and licenses in its README); point \
             {MODELS_ENV} at a copy of it",
            dir.display()
        ))
    }
}
