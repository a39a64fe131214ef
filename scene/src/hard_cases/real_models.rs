//! The **models** family: real models from the shared model folder.

use std::path::Path;

use glam::Vec3;

use super::{case, look, Family, HardCase, MapSpec};
use crate::{load_obj, DirectionalLight, Scene};

/// The cases of the `models` family, in table order, read from `models` (a missing model gives a case
/// whose scene is the load error).
pub(super) fn real_models(models: &Path) -> Vec<HardCase> {
    let load = |file: &str| load_obj(&models.join(file));
    let cornell = case(
        "Cornell box (06)",
        Family::Models,
        "The Cornell box (36 triangles: quads, negative indices, block footprints coplanar with \
         the floor), lit through its open front.",
        Scene::default(),
        Vec3::new(0.35, -0.45, 1.0),
        Some(look(
            Vec3::new(278.0, 273.0, -800.0),
            Vec3::new(278.0, 273.0, 280.0),
        )),
        MapSpec::new(256),
    );
    let veach = case(
        "Veach MIS plates (07)",
        Family::Models,
        "Four zero-thickness plates at grazing angles over a large floor and wall.",
        Scene::default(),
        Vec3::new(0.0, -0.35, -1.0),
        Some(look(Vec3::new(0.0, 2.0, 15.0), Vec3::new(0.0, -2.0, 2.5))),
        MapSpec::new(256),
    );
    let pine = case(
        "small pine (08)",
        Family::Models,
        "A pine of 82 zero-thickness foliage cards (1,650 triangles) on a ground plane.",
        Scene::default(),
        DirectionalLight::slanted().direction,
        None,
        MapSpec::new(256),
    );
    let sponza = case(
        "Sponza (04)",
        Family::Models,
        "Dabrovic Sponza (66K triangles, 10 duplicate triangles), seen from inside the atrium \
         under a steep sun.",
        Scene::default(),
        Vec3::new(0.3, -1.0, 0.12),
        Some(look(Vec3::new(-12.0, 2.5, 0.5), Vec3::new(4.0, 4.0, -1.0))),
        MapSpec::new(512),
    );
    let conference = case(
        "conference room (05)",
        Family::Models,
        "The conference room (277K triangles, thin chair legs, large floor).",
        Scene::default(),
        Vec3::new(0.35, -1.0, 0.25),
        Some(look(
            Vec3::new(-900.0, 400.0, 550.0),
            Vec3::new(400.0, 80.0, -300.0),
        )),
        MapSpec::new(512),
    );
    let files = [
        (cornell, load("06_cornell_box/cornell_box.obj")),
        (veach, load("07_veach_mi_plates.obj")),
        (
            pine,
            load("08_smallpine_1650.obj").map(|s| s.with_ground_plane()),
        ),
        (sponza, load("04_dabrovic_sponza_66k.obj")),
        (conference, load("05_conference_clean_277k.obj")),
    ];
    files
        .into_iter()
        .map(|(c, scene)| HardCase { scene, ..c })
        .collect()
}
