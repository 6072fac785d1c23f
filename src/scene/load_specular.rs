//! KHR_materials_ior and KHR_materials_specular: the dielectric Fresnel of a glTF material
//! ([`DielectricSpecular`]), read from the material's extensions.
//!
//! - KHR_materials_ior: `{"ior": n}`, n ≥ 1 or exactly 0 (the extension's stand-in for `f0 = 1`); 1.5 by default.
//! - KHR_materials_specular: `{"specularFactor": w, "specularColorFactor": [r, g, b]}`, w in [0, 1] (1 by default),
//!   the colour non-negative (1 by default; above 1 allowed, the product with the ior's reflectance is clamped to
//!   1). Its `specularTexture` and `specularColorTexture` are not read: the factors apply alone, and the caller
//!   names the textures in its warning.
//!
//! Without either extension the material keeps [`DielectricSpecular::DEFAULT`] exactly.

use serde_json::Value;

use super::material::DielectricSpecular;

/// What the extensions object of a material gives the dielectric, and which of their parts sunshade does not draw
/// (`ignored`, for the material's warning). Errors name the extension and the value.
pub fn dielectric_specular(
    extensions: &std::collections::BTreeMap<String, Value>,
    ignored: &mut Vec<String>,
) -> Result<DielectricSpecular, String> {
    let ior_ext = extensions.get("KHR_materials_ior");
    let specular_ext = extensions.get("KHR_materials_specular");
    if ior_ext.is_none() && specular_ext.is_none() {
        return Ok(DielectricSpecular::DEFAULT);
    }
    let number = |ext: Option<&Value>, name: &str, key: &str, default: f64| -> Result<f64, String> {
        match ext.and_then(|x| x.get(key)) {
            None => Ok(default),
            Some(v) => v.as_f64().filter(|v| v.is_finite()).ok_or_else(|| format!("{name} {key} {v} is not a number")),
        }
    };
    let ior = number(ior_ext, "KHR_materials_ior", "ior", 1.5)?;
    if !(ior == 0.0 || ior >= 1.0) {
        return Err(format!("KHR_materials_ior ior {ior} must be at least 1 (or 0)"));
    }
    let weight = number(specular_ext, "KHR_materials_specular", "specularFactor", 1.0)?;
    if !(0.0..=1.0).contains(&weight) {
        return Err(format!("KHR_materials_specular specularFactor {weight} must lie in [0, 1]"));
    }
    let colour = match specular_ext.and_then(|x| x.get("specularColorFactor")) {
        None => [1.0; 3],
        Some(v) => {
            let c: Vec<f64> =
                v.as_array().map_or(Vec::new(), |a| a.iter().map(|x| x.as_f64().unwrap_or(-1.0)).collect());
            if c.len() != 3 || !c.iter().all(|x| x.is_finite() && *x >= 0.0) {
                return Err(format!("KHR_materials_specular specularColorFactor {v} must be 3 non-negative numbers"));
            }
            [c[0], c[1], c[2]]
        }
    };
    if let Some(x) = specular_ext {
        for texture in ["specularTexture", "specularColorTexture"] {
            if x.get(texture).is_some() {
                ignored.push(format!("KHR_materials_specular {texture} (its factors apply alone)"));
            }
        }
    }
    Ok(DielectricSpecular::from_extensions(ior, weight, colour))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn read(x: Value) -> (Result<DielectricSpecular, String>, Vec<String>) {
        let map: std::collections::BTreeMap<String, Value> = serde_json::from_value(x).unwrap();
        let mut ignored = Vec::new();
        (dielectric_specular(&map, &mut ignored), ignored)
    }

    #[test]
    fn reads_ior_and_specular_as_the_extensions_define_them() {
        assert_eq!(read(json!({})).0.unwrap(), DielectricSpecular::DEFAULT);
        // ior 1.5 written out is the default exactly.
        assert_eq!(read(json!({"KHR_materials_ior": {"ior": 1.5}})).0.unwrap(), DielectricSpecular::DEFAULT);
        let glass = read(json!({"KHR_materials_ior": {"ior": 2.0}})).0.unwrap();
        assert_eq!(glass, DielectricSpecular { f0: [(1.0f64 / 9.0) as f32; 3], f90: 1.0 });
        let (tinted, ignored) = read(json!({"KHR_materials_specular": {
            "specularFactor": 0.5, "specularColorFactor": [1.0, 0.5, 30.0], "specularTexture": {"index": 0}}}));
        assert_eq!(tinted.unwrap(), DielectricSpecular { f0: [0.02, 0.01, 0.5], f90: 0.5 });
        assert_eq!(ignored.len(), 1);
        assert!(ignored[0].contains("specularTexture"));
        // ior 0: f0 = 1 before the colour and the weight.
        let sg = read(
            json!({"KHR_materials_ior": {"ior": 0}, "KHR_materials_specular": {"specularColorFactor": [0.2, 0.3, 0.4]}}),
        );
        assert_eq!(sg.0.unwrap(), DielectricSpecular { f0: [0.2, 0.3, 0.4], f90: 1.0 });
        for bad in [
            json!({"KHR_materials_ior": {"ior": 0.5}}),
            json!({"KHR_materials_specular": {"specularFactor": 1.5}}),
            json!({"KHR_materials_specular": {"specularColorFactor": [1, -1, 1]}}),
            json!({"KHR_materials_specular": {"specularColorFactor": [1, 1]}}),
            json!({"KHR_materials_ior": {"ior": "glass"}}),
        ] {
            let e = read(bad.clone()).0.unwrap_err();
            assert!(e.starts_with("KHR_materials_") && !e.contains('\n'), "{bad}: {e}");
        }
    }
}
