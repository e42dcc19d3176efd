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
        let cpu = x86::Cpu::read();
        x86::FEATURES.iter().filter(|f| f.compiled && !cpu.has(f)).map(|f| f.name).collect()
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        Vec::new()
    }
}

/// `Err` with the sentence for the user when this CPU lacks an extension the binary was
/// compiled to use: what `hdw` and the Python extension check before anything else.
pub fn check() -> Result<(), String> {
    let missing = missing_features();
    if missing.is_empty() { Ok(()) } else { Err(refusal(&missing)) }
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

    /// Which `cpuid` output word holds an extension's bit.
    #[derive(Clone, Copy)]
    pub enum Word {
        /// Leaf 1, ECX.
        Leaf1Ecx,
        /// Leaf 7 (subleaf 0), EBX.
        Leaf7Ebx,
        /// Leaf 0x8000_0001, ECX.
        Ext1Ecx,
    }

    /// The register state the OS must save for an extension's instructions to work.
    #[derive(Clone, Copy, PartialEq)]
    pub enum OsState {
        None,
        /// The 256-bit registers.
        Avx,
        /// The 512-bit registers and the mask registers.
        Avx512,
    }

    /// An extension: its name, whether the binary was compiled to use it, and where the
    /// CPU reports it.
    pub struct Feature {
        pub name: &'static str,
        pub compiled: bool,
        word: Word,
        bit: u32,
        os: OsState,
    }

    macro_rules! feature {
        ($name:tt, $word:ident, $bit:expr, $os:ident) => {
            Feature {
                name: $name,
                compiled: cfg!(target_feature = $name),
                word: Word::$word,
                bit: $bit,
                os: OsState::$os,
            }
        };
    }

    pub const FEATURES: &[Feature] = &[
        feature!("sse3", Leaf1Ecx, 0, None),
        feature!("ssse3", Leaf1Ecx, 9, None),
        feature!("fma", Leaf1Ecx, 12, Avx),
        feature!("sse4.1", Leaf1Ecx, 19, None),
        feature!("sse4.2", Leaf1Ecx, 20, None),
        feature!("movbe", Leaf1Ecx, 22, None),
        feature!("popcnt", Leaf1Ecx, 23, None),
        feature!("avx", Leaf1Ecx, 28, Avx),
        feature!("f16c", Leaf1Ecx, 29, Avx),
        feature!("bmi1", Leaf7Ebx, 3, None),
        feature!("avx2", Leaf7Ebx, 5, Avx),
        feature!("bmi2", Leaf7Ebx, 8, None),
        feature!("avx512f", Leaf7Ebx, 16, Avx512),
        feature!("avx512dq", Leaf7Ebx, 17, Avx512),
        feature!("avx512bw", Leaf7Ebx, 30, Avx512),
        feature!("avx512vl", Leaf7Ebx, 31, Avx512),
        feature!("lzcnt", Ext1Ecx, 5, None),
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

        /// Whether the CPU and the OS support `f`.
        pub fn has(&self, f: &Feature) -> bool {
            let word = match f.word {
                Word::Leaf1Ecx => self.leaf1_ecx,
                Word::Leaf7Ebx => self.leaf7_ebx,
                Word::Ext1Ecx => self.ext1_ecx,
            };
            let os = match f.os {
                OsState::None => true,
                OsState::Avx => self.os_avx,
                OsState::Avx512 => self.os_avx512,
            };
            word & (1 << f.bit) != 0 && os
        }

        /// Whether the CPU and the OS support the extension called `name` (false for a
        /// name not in [`FEATURES`]).
        #[cfg(test)]
        pub fn supports(&self, name: &str) -> bool {
            FEATURES.iter().any(|f| f.name == name && self.has(f))
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
        for f in x86::FEATURES {
            if !f.compiled {
                let (name, std_says) = match f.name {
                    n @ "avx512f" => (n, std::arch::is_x86_feature_detected!("avx512f")),
                    n @ "avx512dq" => (n, std::arch::is_x86_feature_detected!("avx512dq")),
                    n @ "avx512bw" => (n, std::arch::is_x86_feature_detected!("avx512bw")),
                    n @ "avx512vl" => (n, std::arch::is_x86_feature_detected!("avx512vl")),
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
