//! A binary built for one CPU (`.cargo/config.toml` builds for the build machine's) must not
//! die with "illegal instruction" on another: before anything else runs, check that this
//! machine has every instruction-set extension the binary was compiled to use, and name the
//! missing ones and the portable build if it does not.

/// The extensions the binary was compiled to use that this CPU lacks (empty elsewhere than
/// on x86-64).
pub fn missing_features() -> Vec<&'static str> {
    #[cfg(target_arch = "x86_64")]
    {
        // `cfg!` is what the compiler was allowed to use; the macro asks the CPU (cpuid).
        macro_rules! check {
            ($($f:tt),* $(,)?) => {{
                let mut missing = Vec::new();
                $(
                    if cfg!(target_feature = $f) && !std::arch::is_x86_feature_detected!($f) {
                        missing.push($f);
                    }
                )*
                missing
            }};
        }
        check!(
            "sse3", "ssse3", "sse4.1", "sse4.2", "popcnt", "avx", "avx2", "fma", "bmi1", "bmi2",
            "lzcnt", "f16c", "movbe", "avx512f", "avx512dq", "avx512bw", "avx512vl",
        )
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        Vec::new()
    }
}

/// The sentence for a CPU without `missing`.
pub fn refusal(missing: &[&str]) -> String {
    format!(
        "this build of hdw was compiled for a CPU with {} (the build machine's instruction \
         set), which this machine lacks; build it on this machine, or build a portable one \
         with RUSTFLAGS=\"-C target-cpu=x86-64\" (cargo build, or pip install ./python)",
        missing.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_test_machine_runs_what_it_built() {
        // Tests run where they are built: nothing the build used can be missing.
        assert_eq!(missing_features(), Vec::<&str>::new());
    }

    #[test]
    fn the_refusal_names_the_extensions_and_the_portable_build() {
        let s = refusal(&["avx2", "fma"]);
        assert!(s.contains("avx2, fma"), "{s}");
        assert!(s.contains("target-cpu=x86-64"), "{s}");
    }
}
