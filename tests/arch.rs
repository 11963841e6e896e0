//! The throughput model of the thesis hardware (`raypipe arch`): cycle counts against hand
//! counts, events of a hand-built scene, monotonicity, determinism.

use golden::Ray64;
use proptest::prelude::*;
use raypipe::arch::model::{leaf_cycles, rti_cycles, trav_cycles};
use raypipe::arch::{estimate, gather, ArchParams, RtiCycles, SceneEvents};
use raypipe::scene::Scene;

/// One leaf by hand with the default parameters: n = 16, b = min(4, 3 + 1) = 4, so 64 rays a
/// round, a triangle every 4 cycles, latency 10, 12 DRAM bytes a cycle, 36-byte rays, 16-byte
/// results.
#[test]
fn a_leaf_costs_the_hand_count() {
    let p = ArchParams::default();
    assert_eq!((p.packet(), p.cadence()), (64, 4));
    let mut c = RtiCycles::default();
    // 100 rays, 5 triangles: 2 rounds; load 100·36/12 = 300; stream 2·4·5 = 40; drain 2·10 = 20;
    // store ⌈100·16/12⌉ = ⌈133.3⌉ = 134
    leaf_cycles(&p, 100, 5, &mut c);
    assert_eq!(c, RtiCycles { rounds: 2, ray_load: 300, stream: 40, drain: 20, store: 134, total: 494, tests: 500 });
    // overlapped: max(40 + 20, 300 + 134) = 434
    let mut o = RtiCycles::default();
    leaf_cycles(&ArchParams { overlap_io: true, ..p.clone() }, 100, 5, &mut o);
    assert_eq!(o.total, 434);
    // a leaf no ray tests costs nothing
    let mut z = RtiCycles::default();
    leaf_cycles(&p, 0, 9, &mut z);
    assert_eq!(z, RtiCycles::default());
    // the peak: 16 pipelines · 100 MHz · 4 / 4
    assert_eq!(p.rti_peak(), 1.6e9);
    // buffers beyond the cadence find no cycle: 8 buffers use 4
    assert_eq!(ArchParams { buffers: 8, ..p.clone() }.packet(), 64);
    assert_eq!(ArchParams { buffers: 2, ..p }.packet(), 32);
}

/// Two triangles ten units apart, one per leaf; three rays whose work is known by hand.
fn two_leaf_scene() -> Scene {
    let dir = std::env::temp_dir().join(format!("raypipe-arch-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("two.obj");
    std::fs::write(&p, "v -1 -1 0\nv 1 -1 2\nv 0 1 1\nv 9 -1 0\nv 11 -1 2\nv 10 1 1\nf 1 2 3\nf 4 5 6\n").unwrap();
    let s = Scene::load_obj(&p).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    s
}

#[test]
fn the_events_and_cycles_of_a_hand_built_scene_are_the_hand_count() {
    let scene = two_leaf_scene();
    let b = raypipe::bvh::build(&scene, 1);
    assert_eq!((b.leaf_tris.len(), b.depth), (2, 1));
    // coordinates are scaled into [-1, 1]^3 by a power of two: build the rays in scene units
    let k = scene.scale;
    let rays = [
        // A: straight up through triangle 0: one pass, leaf 0, a hit
        Ray64 { o: [0.0, 0.0, -5.0 * k], d: [0.0, 0.0, 1.0], tmin: 0.0, tmax: f64::INFINITY },
        // B: away from everything: the root misses (0 passes, counted as the 1 entry slot it takes)
        Ray64 { o: [0.0, 0.0, -5.0 * k], d: [0.0, 0.0, -1.0], tmin: 0.0, tmax: f64::INFINITY },
        // C: along x through both boxes, missing both triangles: both leaves, 2 passes
        Ray64 { o: [-5.0 * k, 0.9 * k, 1.9 * k], d: [1.0, 0.0, 0.0], tmin: 0.0, tmax: f64::INFINITY },
    ];
    let e = gather(&engine::Engine::new(1), &scene, &b, 1, 3, |i| rays[i as usize]).unwrap();
    let leaf_of = |t: u32| b.leaf_tris.iter().position(|l| l == &vec![t]).unwrap();
    let mut leaf_rays = vec![0; 2];
    leaf_rays[leaf_of(0)] = 2; // A and C
    leaf_rays[leaf_of(1)] = 1; // C
    assert_eq!(
        e,
        SceneEvents {
            leaf_size: 1,
            depth: 1,
            rays: 3,
            rays_hit: 1,
            leaf_tris: vec![1, 1],
            leaf_rays,
            passes: 1 + 1 + 2,
            bram_boxes: 3,
        }
    );
    let p = ArchParams::default();
    // leaf of triangle 0: 2 rays, 1 round: load 6, stream 4, drain 10, store ⌈32/12⌉ = 3 → 23;
    // leaf of triangle 1: 1 ray: load 3, stream 4, drain 10, store ⌈16/12⌉ = 2 → 19
    let r = rti_cycles(&p, &e);
    assert_eq!((r.rounds, r.ray_load, r.stream, r.drain, r.store, r.total, r.tests), (2, 9, 8, 20, 5, 42, 3));
    // traversal: 4 slots, 1 trip (depth 1 ≤ 32 levels), fill 32 · 16 = 512
    let t = trav_cycles(&p, &e);
    assert_eq!((t.trips, t.slots, t.fill, t.total), (1, 4, 512, 516));
    let est = estimate(&p, &e);
    assert_eq!(est.rti_s, 42.0 / 100e6);
    assert_eq!(est.trav_s, 516.0 / 200e6);
    assert_eq!(est.total_s, 42.0 / 100e6 + 516.0 / 200e6);
    assert_eq!(est.bram_bits, 3 * (192 + 32));
    // a tree deeper than the level pipelines takes ⌈depth / L⌉ trips per pass
    let deep = SceneEvents { depth: 70, ..e.clone() };
    assert_eq!(trav_cycles(&p, &deep).trips, 3);
}

fn events() -> impl Strategy<Value = SceneEvents> {
    (prop::collection::vec((1u32..40, 0u64..400), 1..20), 1u64..1000, 0usize..80).prop_map(|(leaves, passes, depth)| {
        SceneEvents {
            leaf_size: 8,
            depth,
            rays: 100,
            rays_hit: 50,
            leaf_tris: leaves.iter().map(|l| l.0).collect(),
            leaf_rays: leaves.iter().map(|l| l.1).collect(),
            passes,
            bram_boxes: 7,
        }
    })
}

fn params() -> impl Strategy<Value = ArchParams> {
    (1u32..64, 1u32..8, 0u32..6, 1u32..3, 0u32..40, 1u32..64, 1u32..64, 1u32..64, any::<bool>(), 1u32..64, 1u32..3)
        .prop_map(|(n, b, asm, bc, lat, dram, ray, res, overlap, levels, ports)| ArchParams {
            pipelines: n,
            buffers: b,
            tri_assemble: asm,
            tri_broadcast: bc,
            rti_latency: lat,
            dram_bytes_per_cycle: dram,
            ray_bytes: ray,
            result_bytes: res,
            overlap_io: overlap,
            levels,
            ports,
            ..ArchParams::default()
        })
}

proptest! {
    /// All else equal, more pipelines, buffers, DRAM bandwidth, ports or clock never make the
    /// model slower; overlapping I/O never does either. (More level pipelines can: they cut
    /// the trips of a deep tree but lengthen the fill.)
    #[test]
    fn more_hardware_is_never_slower(e in events(), p in params()) {
        let t = |q: ArchParams| estimate(&q, &e).total_s;
        let base = t(p.clone());
        let more = [
            ArchParams { pipelines: p.pipelines + 1, ..p.clone() },
            ArchParams { buffers: p.buffers + 1, ..p.clone() },
            ArchParams { dram_bytes_per_cycle: p.dram_bytes_per_cycle + 1, ..p.clone() },
            ArchParams { ports: p.ports + 1, ..p.clone() },
            ArchParams { rti_mhz: p.rti_mhz * 1.5, ..p.clone() },
            ArchParams { trav_mhz: p.trav_mhz * 1.5, ..p.clone() },
            ArchParams { overlap_io: true, ..p.clone() },
        ];
        for q in more {
            let faster = t(q.clone());
            prop_assert!(faster <= base, "{:?}: {} > {}", q, faster, base);
        }
        // the RTI tests performed do not depend on the hardware
        prop_assert_eq!(estimate(&p, &e).rti.tests, e.rti_tests());
    }
}

/// The events, and so every figure, do not depend on threads or chunking.
#[test]
fn events_do_not_depend_on_threads_or_chunks() {
    let scene = Scene::builtin();
    let b = raypipe::bvh::build(&scene, 4);
    let gen = raypipe::traverse::CameraRays::new(&scene, 3000, 7);
    let one = gather(&engine::Engine::new(3000).with_threads(Some(1)), &scene, &b, 4, 3000, |k| gen.ray(k)).unwrap();
    for (chunk, threads) in [(1, Some(2)), (37, Some(2)), (512, None)] {
        let e = engine::Engine::new(chunk).with_threads(threads);
        assert_eq!(gather(&e, &scene, &b, 4, 3000, |k| gen.ray(k)).unwrap(), one, "chunk {chunk}");
    }
}

#[test]
fn bad_parameters_are_clear_errors() {
    for (p, flag) in [
        (ArchParams { pipelines: 0, ..ArchParams::default() }, "--pipelines"),
        (ArchParams { dram_bytes_per_cycle: 0, ..ArchParams::default() }, "--dram-bytes"),
        (ArchParams { tri_assemble: 0, tri_broadcast: 0, ..ArchParams::default() }, "--tri-assemble"),
        (ArchParams { rti_mhz: f64::NAN, ..ArchParams::default() }, "--rti-mhz"),
        (ArchParams { trav_mhz: 0.0, ..ArchParams::default() }, "--trav-mhz"),
    ] {
        assert!(p.check().unwrap_err().contains(flag), "{flag}");
    }
}
