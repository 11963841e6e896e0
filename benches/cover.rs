//! criterion benchmark of `raypipe cover`: measuring the functional coverage of a written
//! vector set (an RTI fp16 set of 51,000 vectors, 3,000 per class), read row by row from disk
//! as the command does. Throughput is vectors; a 1 M-vector set takes 1 M / that rate
//! (docs/coverage.md). Run: `cargo bench --bench cover`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use vectors::cover::Coverage;

fn bench_cover(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("raypipe-bench-cover-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut req = vectors::gen::Request::new(vectors::gen::Unit::Rti, "fp16".parse().expect("format"));
    req.count = 3000;
    req.command = "bench".into();
    let set = vectors::gen::generate(&req).expect("set");
    vectors::write::write_set(&set, &dir).expect("written");
    let rows = set.manifest.files[0].rows as u64;
    // the manifest as written (with each file's hash), as `raypipe cover` reads it
    let text = std::fs::read_to_string(dir.join("manifest.json")).expect("manifest");
    let m: vectors::manifest::Manifest = serde_json::from_str(&text).expect("manifest json");
    let mut g = c.benchmark_group("cover");
    g.throughput(Throughput::Elements(rows));
    g.bench_function("rti_fp16_set_from_disk", |b| b.iter(|| Coverage::measure_dir(&dir, &m).expect("measured")));
    g.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(std::time::Duration::from_secs(5)).warm_up_time(std::time::Duration::from_millis(300));
    targets = bench_cover
}
criterion_main!(benches);
