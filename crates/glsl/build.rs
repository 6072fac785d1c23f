//! Link shaderc statically against Debian's archives.
//!
//! These link directives belong to this library crate, so they reach every binary that depends on it: sunshade
//! itself, and sunshade's build script, which compiles the shaders ahead of time.
//!
//! Debian's shared `libshaderc.so.1` is under-linked (glslang and SPIRV-Tools symbols stay undefined), so the
//! `shaderc` crate is built with `prefer-static-linking`, which links `libshaderc_combined.a`. On Debian that archive
//! holds only shaderc's own objects, so the glslang and SPIRV-Tools archives it needs are linked here as well.
//! See `docs/platform.md` of sunshade.

use std::path::Path;

const STATIC_LIBS: [&str; 8] = [
    "glslang",
    "MachineIndependent",
    "OSDependent",
    "GenericCodeGen",
    "OGLCompiler",
    "SPIRV",
    "SPIRV-Tools-opt",
    "SPIRV-Tools",
];

fn main() {
    // Every rerun-if line comes first, before any early exit.
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=SHADERC_LIB_DIR");
    let lib_dir = std::env::var("SHADERC_LIB_DIR").unwrap_or_else(|_| {
        let arch = std::env::var("CARGO_CFG_TARGET_ARCH").unwrap_or_else(|_| "x86_64".into());
        let debian_arch = if arch == "x86" { "i386".to_string() } else { arch };
        format!("/usr/lib/{debian_arch}-linux-gnu")
    });
    let missing: Vec<String> = std::iter::once("shaderc_combined")
        .chain(STATIC_LIBS)
        .map(|l| format!("lib{l}.a"))
        .filter(|f| !Path::new(&lib_dir).join(f).exists())
        .collect();
    if !missing.is_empty() {
        eprintln!(
            "sunshade build: {} not found in {lib_dir}; install the packages libshaderc-dev glslang-dev spirv-tools \
             (run `make setup`), or set SHADERC_LIB_DIR",
            missing.join(", ")
        );
        std::process::exit(1);
    }
    println!("cargo:rustc-link-search=native={lib_dir}");
    for lib in STATIC_LIBS {
        println!("cargo:rustc-link-lib=static={lib}");
    }
}
