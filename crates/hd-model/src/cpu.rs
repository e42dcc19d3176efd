//! A binary built for one CPU (`.cargo/config.toml` builds for the build machine's) must not
//! die with "illegal instruction" on another: before anything else runs, check that this
//! machine has every instruction-set extension the binary was compiled to use, and name the
//! missing ones and the portable build if it does not.
//!
//! The CPU is asked directly (the `cpuid` instruction, and `xgetbv` for whether the
//! operating system saves the wide registers). `is_x86_feature_detected!` cannot be used:
//! for an extension the binary was compiled with it answers "yes" without asking, so a
//! check built on it never fails (measured: a build with AVX-512 enabled passed it on this
//! AVX-512-less machine and died in the argument parser).

/// The extensions the binary was compiled to use that this CPU lacks (empty elsewhere than
/// on x86-64).
pub fn missing_features() -> Vec<&'static str> {
    #[cfg(target_arch = "x86_64")]
    {
        let has = x86::Cpu::read();
        x86::FEATURES
            .iter()
            .filter(|(name, compiled, _)| *compiled && !has.supports(name))
            .map(|(name, _, _)| *name)
            .collect()
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

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::{__cpuid, __cpuid_count};

    /// Where each extension's bit is: (name, compiled in, (register, bit)) with the
    /// register one of "1c" (leaf 1, ECX), "7b" (leaf 7, EBX) and "e1c" (leaf 0x8000_0001,
    /// ECX).
    pub const FEATURES: &[(&str, bool, (&str, u32))] = &[
        ("sse3", cfg!(target_feature = "sse3"), ("1c", 0)),
        ("ssse3", cfg!(target_feature = "ssse3"), ("1c", 9)),
        ("fma", cfg!(target_feature = "fma"), ("1c", 12)),
        ("sse4.1", cfg!(target_feature = "sse4.1"), ("1c", 19)),
        ("sse4.2", cfg!(target_feature = "sse4.2"), ("1c", 20)),
        ("movbe", cfg!(target_feature = "movbe"), ("1c", 22)),
        ("popcnt", cfg!(target_feature = "popcnt"), ("1c", 23)),
        ("avx", cfg!(target_feature = "avx"), ("1c", 28)),
        ("f16c", cfg!(target_feature = "f16c"), ("1c", 29)),
        ("bmi1", cfg!(target_feature = "bmi1"), ("7b", 3)),
        ("avx2", cfg!(target_feature = "avx2"), ("7b", 5)),
        ("bmi2", cfg!(target_feature = "bmi2"), ("7b", 8)),
        ("avx512f", cfg!(target_feature = "avx512f"), ("7b", 16)),
        ("avx512dq", cfg!(target_feature = "avx512dq"), ("7b", 17)),
        ("avx512bw", cfg!(target_feature = "avx512bw"), ("7b", 30)),
        ("avx512vl", cfg!(target_feature = "avx512vl"), ("7b", 31)),
        ("lzcnt", cfg!(target_feature = "lzcnt"), ("e1c", 5)),
    ];

    /// The CPU's answers, and what the operating system enables.
    pub struct Cpu {
        leaf1_ecx: u32,
        leaf7_ebx: u32,
        ext1_ecx: u32,
        /// The OS saves the 256-bit registers (AVX) and the 512-bit ones and masks (AVX-512).
        os_avx: bool,
        os_avx512: bool,
    }

    impl Cpu {
        pub fn read() -> Self {
            // `cpuid` exists on every x86-64 CPU; leaves above the largest it reports are
            // not read.
            let (max, max_ext) = (__cpuid(0).eax, __cpuid(0x8000_0000).eax);
            let leaf1_ecx = __cpuid(1).ecx;
            let leaf7_ebx = if max >= 7 { __cpuid_count(7, 0).ebx } else { 0 };
            let ext1_ecx = if max_ext >= 0x8000_0001 { __cpuid(0x8000_0001).ecx } else { 0 };
            // OSXSAVE (leaf 1, ECX bit 27) says `xgetbv` may be executed.
            let xcr0 = if leaf1_ecx & (1 << 27) != 0 { xgetbv0() } else { 0 };
            Self {
                leaf1_ecx,
                leaf7_ebx,
                ext1_ecx,
                os_avx: xcr0 & 0b110 == 0b110,
                os_avx512: xcr0 & 0b1110_0110 == 0b1110_0110,
            }
        }

        /// Whether the CPU and the OS support the extension `name` of [`FEATURES`].
        pub fn supports(&self, name: &str) -> bool {
            let Some(&(_, _, (reg, bit))) = FEATURES.iter().find(|f| f.0 == name) else {
                return false;
            };
            let word = match reg {
                "1c" => self.leaf1_ecx,
                "7b" => self.leaf7_ebx,
                _ => self.ext1_ecx,
            };
            let cpu = word & (1 << bit) != 0;
            let os = if name.starts_with("avx512") {
                self.os_avx512
            } else if matches!(name, "avx" | "avx2" | "fma" | "f16c") {
                self.os_avx
            } else {
                true
            };
            cpu && os
        }
    }

    /// XCR0, the register-state components the OS saves on a context switch.
    fn xgetbv0() -> u64 {
        let (lo, hi): (u32, u32);
        // SAFETY: called only when CPUID says OSXSAVE, i.e. `xgetbv` is enabled; it reads
        // a register and touches no memory.
        unsafe {
            std::arch::asm!("xgetbv", in("ecx") 0u32, out("eax") lo, out("edx") hi,
                options(nomem, nostack, preserves_flags));
        }
        (u64::from(hi) << 32) | u64::from(lo)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_test_machine_runs_what_it_built() {
        // Tests run where they are built: nothing the build used can be missing.
        assert_eq!(missing_features(), Vec::<&str>::new());
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn the_cpu_is_asked_not_the_build() {
        // SSE3 is read from the same word as most of the others and every x86-64 CPU since
        // 2005 has it; an unknown name is not supported.
        let cpu = x86::Cpu::read();
        assert!(cpu.supports("sse3"), "every x86-64 CPU since 2005 has SSE3");
        assert!(!cpu.supports("no-such-extension"));
        // What the CPU reports agrees with the standard library's own detection wherever
        // that detection is not short-circuited by the build (features not compiled in).
        for &(name, compiled, _) in x86::FEATURES {
            if !compiled {
                let std_says = match name {
                    "avx512f" => std::arch::is_x86_feature_detected!("avx512f"),
                    "avx512dq" => std::arch::is_x86_feature_detected!("avx512dq"),
                    "avx512bw" => std::arch::is_x86_feature_detected!("avx512bw"),
                    "avx512vl" => std::arch::is_x86_feature_detected!("avx512vl"),
                    _ => continue,
                };
                assert_eq!(cpu.supports(name), std_says, "{name}");
            }
        }
    }

    #[test]
    fn the_refusal_names_the_extensions_and_the_portable_build() {
        let s = refusal(&["avx2", "fma"]);
        assert!(s.contains("avx2, fma"), "{s}");
        assert!(s.contains("target-cpu=x86-64"), "{s}");
    }
}
