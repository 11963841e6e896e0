//! The machine a measurement ran on, as every table of figures names it: the CPU model, the
//! cores, and the instruction-set extensions the kernels use.

/// `"<CPU model> (<n> cores; avx2 f16c fma avx512f …)"`, from `/proc/cpuinfo` (Linux) and
/// run-time feature detection; `"unknown CPU"` where the model cannot be read.
pub fn machine() -> String {
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".to_string());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    format!("{model} ({cores} cores; {})", isa().join(" "))
}

/// The instruction-set extensions of this machine the kernels can use.
pub fn isa() -> Vec<&'static str> {
    let mut v = Vec::new();
    #[cfg(target_arch = "x86_64")]
    {
        macro_rules! has {
            ($($f:tt),*) => {$(
                if std::arch::is_x86_feature_detected!($f) {
                    v.push($f);
                }
            )*};
        }
        has!("avx2", "f16c", "fma", "avx512f", "avx512dq", "avx512bw", "avx512vl", "avx512fp16", "avx512bf16");
    }
    if v.is_empty() {
        v.push("no SIMD kernels");
    }
    v
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_machine_line_names_the_cores_and_the_isa() {
        let m = super::machine();
        assert!(m.contains(" cores; "), "{m}");
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            assert!(m.contains("avx2"), "{m}");
        }
    }
}
