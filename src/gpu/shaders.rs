//! GLSL sources from `shaders/`, embedded in the binary, compiled to SPIR-V at run time by shaderc.
//!
//! `#include "name.glsl"` resolves against the embedded files, so the binary runs from any directory.
//! A compile error reports the file and line (shaderc's `file:line: error: ...`).

/// Every file in `shaders/`, by name.
pub const SOURCES: &[(&str, &str)] = &[
    ("bindings.glsl", include_str!("../../shaders/bindings.glsl")),
    ("math.glsl", include_str!("../../shaders/math.glsl")),
    ("radiometry.glsl", include_str!("../../shaders/radiometry.glsl")),
    ("brdf.glsl", include_str!("../../shaders/brdf.glsl")),
    ("shade.glsl", include_str!("../../shaders/shade.glsl")),
    ("transform.glsl", include_str!("../../shaders/transform.glsl")),
    ("scene.vert", include_str!("../../shaders/scene.vert")),
    ("scene.frag", include_str!("../../shaders/scene.frag")),
];

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_embedded_stage_compiles() {
        for (name, _) in SOURCES.iter().filter(|(n, _)| !n.ends_with(".glsl")) {
            for defines in [
                &["SUNSHADE_F32_BARYCENTRICS"][..],
                &["SUNSHADE_F64_BARYCENTRICS"][..],
                &["SUNSHADE_DEVICE_INTERPOLATION"][..],
                &["SUNSHADE_F64_BARYCENTRICS", "SUNSHADE_NAIVE_MATH"][..],
            ] {
                let words = compile(name, SOURCES, defines).unwrap_or_else(|e| panic!("{e}"));
                assert_eq!(words[0], 0x0723_0203, "{name}: not SPIR-V");
            }
        }
    }

    #[test]
    fn errors_name_file_and_line() {
        let sources = [
            ("inc.glsl", "float f() {\n  return 1.0;\n}\nfloat g() { return undefined_name; }\n"),
            (
                "broken.frag",
                "#version 450\n#include \"inc.glsl\"\nlayout(location=0) out vec4 o;\nvoid main() { o = vec4(f()); }\n",
            ),
            ("missing.frag", "#version 450\n#include \"nowhere.glsl\"\nvoid main() {}\n"),
        ];
        let err = compile("broken.frag", &sources, &[]).unwrap_err();
        assert!(err.contains("inc.glsl:4"), "{err}");
        let err = compile("missing.frag", &sources, &[]).unwrap_err();
        assert!(err.contains("missing.frag:2") && err.contains("nowhere.glsl"), "{err}");
    }
}
