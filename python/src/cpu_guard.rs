//! The CPU check of a build made for another machine (`hd_model::cpu`), run when the
//! shared library is loaded: before Python calls into it, because PyO3's module set-up,
//! compiled for the build machine like everything else, already uses its instructions
//! (measured: a build with AVX-512 enabled, imported on this AVX-512-less machine, died
//! with "illegal instruction" in that set-up, before the module's own first line). A CPU
//! that lacks an extension gets the sentence on stderr and the process ends with status 1,
//! which is what would otherwise happen with no sentence.

/// The loader runs the functions listed in `.init_array` when it maps the library.
#[cfg(target_os = "linux")]
#[used]
#[unsafe(link_section = ".init_array")]
static CHECK_ON_LOAD: extern "C" fn() = check_on_load;

#[cfg(target_os = "linux")]
extern "C" fn check_on_load() {
    if let Err(why) = hd_model::cpu::check() {
        eprintln!("hdw: {why}");
        std::process::exit(1);
    }
}
