//! Link shaderc statically against Debian's archives.
//!
//! Debian's shared `libshaderc.so.1` is under-linked (glslang and SPIRV-Tools symbols stay undefined), so the
//! `shaderc` crate is built with `prefer-static-linking`, which links `libshaderc_combined.a`. On Debian that archive
//! holds only shaderc's own objects, so the glslang and SPIRV-Tools archives it needs are linked here as well.
//! See `docs/platform.md` for the measurements behind this.

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
    // Every rerun-if line comes first, before any early return.
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=SHADERC_LIB_DIR");
    let lib_dir = std::env::var("SHADERC_LIB_DIR")
        .unwrap_or_else(|_| "/usr/lib/x86_64-linux-gnu".to_string());
    println!("cargo:rustc-link-search=native={lib_dir}");
    for lib in STATIC_LIBS {
        println!("cargo:rustc-link-lib=static={lib}");
    }
}
