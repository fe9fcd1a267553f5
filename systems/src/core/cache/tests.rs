use super::*;
use crate::navigation::{Costmap, CostmapParams};
use crate::raycast::RayMap;
use crate::world::roads::SurfaceRaster;
use crate::world::{Cell, DistanceField, OccupancyGrid};

/// A structure that counts nothing but its own bytes.
#[derive(Debug, Clone, PartialEq)]
struct Blob {
    tag: u32,
    values: Vec<f32>,
    classes: Vec<u8>,
}

impl Cached for Blob {
    const KIND: &'static str = "blob";
    const FORMAT: u32 = 1;
    fn encode(&self, out: &mut Encoder) {
        out.u32(self.tag);
        out.f32s(&self.values);
        out.byte_runs(&self.classes);
    }
    fn decode(input: &mut Decoder<'_>) -> Result<Self, Malformed> {
        Ok(Blob {
            tag: input.u32()?,
            values: input.f32s()?,
            classes: input.byte_runs()?,
        })
    }
}

fn blob(tag: u32) -> Blob {
    Blob {
        tag,
        values: vec![1.5, -0.0, f32::INFINITY, f32::NAN, 3.25],
        classes: [vec![0; 300], vec![7; 3], vec![1; 40], vec![0; 2]].concat(),
    }
}

fn same(a: &Blob, b: &Blob) {
    assert_eq!(to_bytes(a), to_bytes(b));
}

/// The first request builds and writes the entry, the next reads it back bit for bit.
#[test]
fn an_entry_is_built_once_then_read() {
    let dir = tempfile::tempdir().unwrap();
    let cache = MapCache::in_dir(dir.path().join("nested"));
    let key = CacheKey::new::<Blob>().u64(7);
    let first = cache.get_or_build(&key, || blob(7));
    let second = cache.get_or_build(&key, || panic!("should be read"));
    same(&first, &second);
    assert_eq!(
        cache.stats(),
        CacheStats {
            hits: 1,
            misses: 1,
            rejected: 0,
            write_failures: 0
        }
    );
    assert!(cache.entry_path(&key).unwrap().is_file());
    // no temporary file is left behind
    let names: Vec<_> = std::fs::read_dir(dir.path().join("nested"))
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "{names:?}");
}

/// Another input is another key, and so another entry.
#[test]
fn another_input_misses() {
    let dir = tempfile::tempdir().unwrap();
    let cache = MapCache::in_dir(dir.path());
    cache.get_or_build(&CacheKey::new::<Blob>().f64(0.0), || blob(1));
    let other = cache.get_or_build(&CacheKey::new::<Blob>().f64(-0.0), || blob(2));
    assert_eq!(other.tag, 2);
    assert_eq!(cache.stats().misses, 2);
}

/// A corrupt, truncated, empty or foreign entry is rebuilt and replaced, never read.
#[test]
fn a_damaged_entry_is_rebuilt() {
    let dir = tempfile::tempdir().unwrap();
    let cache = MapCache::in_dir(dir.path());
    let key = CacheKey::new::<Blob>().u64(1);
    let other = CacheKey::new::<Blob>().u64(2);
    cache.get_or_build(&other, || blob(2));
    let path = cache.entry_path(&key).unwrap();
    let good = {
        cache.get_or_build(&key, || blob(1));
        std::fs::read(&path).unwrap()
    };
    let mut flipped = good.clone();
    *flipped.last_mut().unwrap() ^= 1;
    let damaged: Vec<Vec<u8>> = vec![
        flipped,
        good[..good.len() - 3].to_vec(),
        good[..20].to_vec(),
        Vec::new(),
        std::fs::read(cache.entry_path(&other).unwrap()).unwrap(),
        [good.clone(), vec![0]].concat(),
    ];
    for (k, bytes) in damaged.iter().enumerate() {
        std::fs::write(&path, bytes).unwrap();
        let before = cache.stats();
        let v = cache.get_or_build(&key, || blob(1));
        same(&v, &blob(1));
        let after = cache.stats();
        assert_eq!(after.rejected, before.rejected + 1, "case {k}");
        assert_eq!(after.misses, before.misses + 1, "case {k}");
        // replaced by a good entry
        assert_eq!(std::fs::read(&path).unwrap(), good, "case {k}");
    }
}

/// A cache folder that cannot be made costs the build, not the result.
#[test]
fn an_unwritable_folder_still_builds() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a file");
    std::fs::write(&file, b"not a folder").unwrap();
    let cache = MapCache::in_dir(file.join("cache"));
    let key = CacheKey::new::<Blob>();
    for _ in 0..2 {
        same(&cache.get_or_build(&key, || blob(3)), &blob(3));
    }
    let s = cache.stats();
    assert_eq!((s.hits, s.misses, s.write_failures), (0, 2, 2));
}

/// With no folder every structure is built and nothing is written.
#[test]
fn a_disabled_cache_builds_every_time() {
    let cache = MapCache::disabled();
    let key = CacheKey::new::<Blob>();
    let mut built = 0;
    for _ in 0..2 {
        cache.get_or_build(&key, || {
            built += 1;
            blob(4)
        });
    }
    assert_eq!(built, 2);
    assert!(cache.entry_path(&key).is_none());
}

/// Runs of bytes come back as they were, and a run longer than its length is refused.
#[test]
fn byte_runs_round_trip() {
    for cells in [vec![], vec![5], vec![0, 0, 1, 1, 1, 0], vec![9; 10_000]] {
        let mut e = Encoder { buf: Vec::new() };
        e.byte_runs(&cells);
        let mut d = Decoder::new(&e.buf);
        assert_eq!(d.byte_runs().unwrap(), cells);
        d.finish().unwrap();
    }
    let mut e = Encoder { buf: Vec::new() };
    e.usize(3);
    e.u8(1);
    e.u32(4);
    assert!(Decoder::new(&e.buf).byte_runs().is_err());
}

fn hospital() -> OccupancyGrid {
    let path = crate::core::source::source_path("assets/maps/hospital/hospital.yaml");
    crate::world::map_file::load_map(&path).unwrap()
}

/// The hospital's ray caster, likelihood field and costmap read from the cache are the ones
/// built, byte for byte, and cast the same rays; one changed cell misses every entry.
#[test]
fn map_structures_from_the_cache_are_the_built_ones() {
    let dir = tempfile::tempdir().unwrap();
    let cache = MapCache::in_dir(dir.path());
    let grid = hospital();
    let params = CostmapParams::default();
    let build = |cache: &MapCache, grid: &OccupancyGrid| {
        (
            RayMap::from_grid_cached(grid, cache),
            DistanceField::new_cached(grid, 2.0, cache),
            Costmap::from_grid_cached(grid, &params, cache),
        )
    };
    let plain = (
        RayMap::from_grid(&grid),
        DistanceField::new(&grid, 2.0),
        Costmap::from_grid(&grid, &params),
    );
    let cold = build(&cache, &grid);
    let warm = build(&cache, &grid);
    assert_eq!(cache.stats().misses, 3);
    assert_eq!(cache.stats().hits, 3);
    for (rays, field, costmap) in [&cold, &warm] {
        assert_eq!(to_bytes(rays), to_bytes(&plain.0));
        assert_eq!(to_bytes(field), to_bytes(&plain.1));
        assert_eq!(costmap, &plain.2);
    }
    let (mut a, mut b) = (vec![0.0f32; 1081], vec![0.0f32; 1081]);
    for k in 0..50 {
        let p = [10.0 + k as f32 * 0.9, 15.0 + (k % 7) as f32];
        plain.0.cast_scan(p, -2.3, 0.0043, 20.0, &mut a);
        warm.0.cast_scan(p, -2.3, 0.0043, 20.0, &mut b);
        assert_eq!(
            a.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            b.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
        let angle = k as f32 * 0.37;
        assert_eq!(
            plain.0.cast(p, angle, 20.0).to_bits(),
            warm.0.cast(p, angle, 20.0).to_bits()
        );
    }
    // one cell changed: every structure is built again, and is that map's
    let mut edited = grid.clone();
    let (c, r) = (300, 300);
    let flip = if edited.get(c, r) == Cell::Occupied {
        Cell::Free
    } else {
        Cell::Occupied
    };
    edited.set(c, r, flip);
    let again = build(&cache, &edited);
    assert_eq!(cache.stats().misses, 6);
    assert_eq!(to_bytes(&again.0), to_bytes(&RayMap::from_grid(&edited)));
    assert_ne!(to_bytes(&again.1), to_bytes(&plain.1));
    // another max distance is another field
    DistanceField::new_cached(&grid, 1.0, &cache);
    assert_eq!(cache.stats().misses, 7);
}

/// The park's road raster read from the cache is the one built, and much smaller on disk.
#[test]
fn the_road_raster_from_the_cache_is_the_built_one() {
    let dir = tempfile::tempdir().unwrap();
    let cache = MapCache::in_dir(dir.path());
    let (graph, built) = crate::world::roads::surface_raster::park_fixture();
    let res = crate::world::roads::surface_raster::DEFAULT_RESOLUTION;
    let margin = crate::world::roads::surface_raster::DEFAULT_MARGIN;
    let cold = SurfaceRaster::build_cached(graph, res, margin, &cache);
    let warm = SurfaceRaster::build_cached(graph, res, margin, &cache);
    assert_eq!(cache.stats().hits, 1);
    assert_eq!(&cold, &**built);
    assert_eq!(&warm, &**built);
    let entry = std::fs::read_dir(dir.path())
        .unwrap()
        .next()
        .unwrap()
        .unwrap();
    assert!(entry.metadata().unwrap().len() < built.bytes() as u64 / 4);
    // a wider road is another raster
    let mut wider = graph.clone();
    wider.roads[0].width += 0.5;
    SurfaceRaster::build_cached(&wider, res, margin, &cache);
    assert_eq!(cache.stats().misses, 2);
}

/// A sharing cache hands every world the one copy the first got (built once, with or without a
/// folder); a plain cache hands each its own; and a world that closes a door edits a copy of its
/// own, leaving the others' rays as they were.
#[test]
fn worlds_of_a_sharing_cache_hold_one_ray_map_until_one_edits_it() {
    use crate::raycast::StaticWorld;
    let dir = tempfile::tempdir().unwrap();
    for cache in [MapCache::disabled(), MapCache::in_dir(dir.path())] {
        let sharing = cache.clone().sharing();
        let first = sharing.get_or_build_shared(&CacheKey::new::<Blob>().u64(1), || blob(1));
        let mut builds = 0;
        let second = sharing.get_or_build_shared(&CacheKey::new::<Blob>().u64(1), || {
            builds += 1;
            blob(1)
        });
        assert_eq!(builds, 0);
        assert!(Arc::ptr_eq(&first, &second));
        // a clone shares too; another key is another structure
        let other = sharing
            .clone()
            .get_or_build_shared(&CacheKey::new::<Blob>().u64(2), || blob(2));
        same(&other, &blob(2));
        let plain = cache.get_or_build_shared(&CacheKey::new::<Blob>().u64(1), || blob(1));
        assert!(!Arc::ptr_eq(&first, &plain));
        same(&first, &plain);
    }

    let sharing = MapCache::disabled().sharing();
    let mut a = StaticWorld::new_cached(hospital(), &sharing);
    let b = StaticWorld::new_cached(hospital(), &sharing);
    assert!(std::ptr::eq(a.rays(), b.rays()));
    // along the main corridor, east: a door-like wall 1 m ahead in world a only
    let (p, angle) = ([32.0f32, 16.0f32], 0.0f32);
    let before = b.rays().cast(p, angle, 30.0);
    assert!(before > 5.0, "{before}");
    a.set_region(32.9, 15.0, 33.1, 17.0, Cell::Occupied);
    assert!(!std::ptr::eq(a.rays(), b.rays()));
    assert!(a.rays().cast(p, angle, 30.0) < 1.0);
    assert_eq!(b.rays().cast(p, angle, 30.0).to_bits(), before.to_bits());
    assert_eq!(
        to_bytes(b.rays()),
        to_bytes(&RayMap::from_grid(&hospital()))
    );
}
