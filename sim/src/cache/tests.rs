use super::*;
use crate::{Finished, Simulation};
use systems::core::cache::to_bytes;
use systems::localization::LocalizationMap;
use systems::navigation::NavCostmaps;
use systems::raycast::StaticWorld;
use systems::world::roads::RoadSurface;

/// The map-derived structures of a built world, as bytes.
fn structures(sim: &Simulation) -> Vec<Vec<u8>> {
    let w = sim.world();
    let mut out = vec![to_bytes(w.resource::<StaticWorld>().rays())];
    if let Some(m) = w.get_resource::<LocalizationMap>() {
        out.push(to_bytes(&m.field));
        out.push(to_bytes(&m.rays));
    }
    if let Some(c) = w.get_resource::<NavCostmaps>() {
        out.extend(c.maps.iter().map(|(_, m)| to_bytes(m)));
    }
    if let Some(s) = w.get_resource::<RoadSurface>() {
        out.push(to_bytes(&*s.0));
    }
    out
}

/// A run's summary, event log and localization samples, wall-clock times aside.
fn outputs(done: &Finished) -> String {
    let v = serde_json::to_value(done.summary.deterministic_part()).unwrap();
    format!("{v}\n{:?}\n{:?}", done.log, done.localization)
}

fn run(name: &str, cache: MapCache) -> (Vec<Vec<u8>>, String) {
    let sim = Simulation::load(name)
        .duration(3.0)
        .threads(1)
        .cache(cache)
        .build()
        .unwrap();
    let built = structures(&sim);
    (built, outputs(&sim.run().unwrap()))
}

/// A bundled scenario builds the same structures and runs to the same summary, events and
/// trajectories with no cache, with an empty one (cold) and with a filled one (warm).
#[test]
fn runs_are_the_same_with_and_without_the_cache() {
    // ray caster, likelihood field, costmap; ray caster, road raster
    for (name, entries) in [("hospital_loop", 3), ("park_route_short", 2)] {
        let dir = tempfile::tempdir().unwrap();
        let cache = MapCache::in_dir(dir.path());
        let none = run(name, MapCache::disabled());
        let cold = run(name, cache.clone());
        assert_eq!(cache.stats().misses, entries, "{name}");
        let warm = run(name, cache.clone());
        assert_eq!(cache.stats().hits, entries, "{name}");
        assert_eq!(cache.stats().misses, entries, "{name}");
        assert!(
            none.0 == cold.0 && none.0 == warm.0,
            "{name}: structures differ"
        );
        assert_eq!(none.1, cold.1, "{name}");
        assert_eq!(none.1, warm.1, "{name}");
    }
}

/// A cache folder that cannot be made (its parent is a file) does not fail a run.
#[test]
fn an_unwritable_cache_folder_still_runs() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("file");
    std::fs::write(&file, b"").unwrap();
    let cache = MapCache::in_dir(file.join("cache"));
    let (_, out) = run("maze_run", cache.clone());
    assert!(!out.is_empty());
    assert!(cache.stats().write_failures > 0);
    assert_eq!(cache.stats().hits, 0);
}

/// `sim cache info` counts the entries a build wrote; `sim cache clear` removes them and
/// nothing else.
#[test]
fn info_and_clear_see_the_entries() {
    let dir = tempfile::tempdir().unwrap();
    let keep = dir.path().join("notes.txt");
    std::fs::write(&keep, b"mine").unwrap();
    assert!(info(dir.path()).unwrap().contains("entries: 0"));
    run("maze_run", MapCache::in_dir(dir.path()));
    let text = info(dir.path()).unwrap();
    assert!(text.contains("entries: 1\n"), "{text}");
    assert_eq!(clear(dir.path()).unwrap().0, 1);
    assert!(info(dir.path()).unwrap().contains("entries: 0"));
    assert!(keep.is_file());
    // a folder that does not exist holds no entries
    assert_eq!(clear(&dir.path().join("missing")).unwrap().0, 0);
}
