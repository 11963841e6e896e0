//! Fuzzing of the OBJ reader: any bytes give a scene or a clear error, never a panic; a scene
//! has at least one triangle and every coordinate finite and within [-1, 1] (the power-of-two
//! normalisation). Run: `cargo fuzz run obj -s none` (from the repository root; stable toolchain).
#![no_main]

use libfuzzer_sys::fuzz_target;
use raypipe::scene::Scene;

fuzz_target!(|data: &[u8]| {
    if let Ok(s) = Scene::parse_obj("fuzz.obj", &mut std::io::Cursor::new(data)) {
        assert!(!s.tris.is_empty());
        for t in &s.tris {
            for p in &t.v {
                for &x in p {
                    assert!(x.is_finite() && x.abs() <= 1.0, "coordinate {x}");
                }
            }
        }
        assert!(s.scale > 0.0 && s.scale.is_finite());
    }
});
