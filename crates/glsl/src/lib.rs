//! GLSL → SPIR-V with shaderc, for sunshade's build script (shaders compiled ahead of time) and for its run-time
//! compilation (`SUNSHADE_SHADER_DIR`, development): one function, so both produce the same words. And
//! [`specialize()`]: a module cut down to what one set of specialization constants can run, for the driver.
//!
//! `#include "name.glsl"` resolves against the given sources, so no file system is needed.
//! A compile error reports the file and line (shaderc's `file:line: error: ...`).

/// Compiles `name` from `sources` (with its includes) to SPIR-V words, with these `#define`s.
pub fn compile(name: &str, sources: &[(&str, &str)], defines: &[&str]) -> Result<Vec<u32>, String> {
    let lookup = |n: &str| sources.iter().find(|(k, _)| *k == n).map(|(_, s)| *s);
    let source = lookup(name).ok_or_else(|| format!("no shader named '{name}'"))?;
    let kind = if name.ends_with(".vert") {
        shaderc::ShaderKind::Vertex
    } else if name.ends_with(".frag") {
        shaderc::ShaderKind::Fragment
    } else if name.ends_with(".comp") {
        shaderc::ShaderKind::Compute
    } else {
        return Err(format!("{name}: unknown shader stage (expected .vert, .frag or .comp)"));
    };
    let compiler = shaderc::Compiler::new().map_err(|e| format!("cannot initialise shaderc: {e}"))?;
    let mut options = shaderc::CompileOptions::new().map_err(|e| format!("cannot create shaderc options: {e}"))?;
    options.set_target_env(shaderc::TargetEnv::Vulkan, shaderc::EnvVersion::Vulkan1_3 as u32);
    // No SPIR-V optimisation: the device compiles anyway, and the arithmetic stays exactly as written.
    options.set_optimization_level(shaderc::OptimizationLevel::Zero);
    options.set_warnings_as_errors();
    for d in defines {
        options.add_macro_definition(d, None);
    }
    options.set_include_callback(|requested, _kind, requester, _depth| {
        lookup(requested)
            .map(|content| shaderc::ResolvedInclude {
                resolved_name: requested.to_string(),
                content: content.to_string(),
            })
            .ok_or_else(|| format!("{requester}: cannot find include '{requested}'"))
    });
    let artifact = compiler
        .compile_into_spirv(source, kind, name, "main", Some(&options))
        .map_err(|e| e.to_string().trim().replace('\n', "; "))?;
    Ok(artifact.as_binary().to_vec())
}

pub mod inlined;
pub mod specialize;
pub use inlined::{inlined_instruction_count, inlined_profile, InlinedFunction};
pub use specialize::{instruction_count, specialize};

/// Runs Debian's `spirv-val` (package spirv-tools, installed by sunshade's `make setup`) on a module with Vulkan
/// 1.3's rules: `Err` holds its message, or says that the tool is missing. For tests.
pub fn spirv_val(words: &[u32]) -> Result<(), String> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let path = std::env::temp_dir().join(format!("sunshade-spirv-val-{}-{n}.spv", std::process::id()));
    std::fs::write(&path, words.iter().flat_map(|w| w.to_le_bytes()).collect::<Vec<u8>>())
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let out = std::process::Command::new("spirv-val").args(["--target-env", "vulkan1.3"]).arg(&path).output();
    let _ = std::fs::remove_file(&path);
    let out = out.map_err(|e| format!("spirv-val: {e} (install spirv-tools: make setup)"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!("spirv-val: {}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr)))
    }
}
