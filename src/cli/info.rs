//! `sunshade info`: the Vulkan devices, the one chosen, and the limits that matter here.

use clap::Args;

use super::CliError;
use crate::gpu::{casts_ray_queries, list_devices, ContextOptions};

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Show which device this selector picks: an index or part of a name.
    #[arg(long, value_name = "INDEX|NAME")]
    pub device: Option<String>,
    /// Print the devices as JSON (`devices`, `chosen`).
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: &InfoArgs) -> Result<(), CliError> {
    let options = ContextOptions { device: a.device.clone(), ..ContextOptions::from_env() };
    let (devices, chosen) = list_devices(&options)?;
    if a.json {
        let list: Vec<serde_json::Value> = devices
            .iter()
            .map(|d| {
                serde_json::json!({
                    "index": d.index, "name": d.name, "type": d.type_name(),
                    "api_version": format!("{}.{}.{}", d.api_version.0, d.api_version.1, d.api_version.2),
                    "driver_name": d.driver_name, "driver_info": d.driver_info,
                    "vendor_id": d.vendor_id, "device_id": d.device_id, "driver_version": d.driver_version,
                    "sub_pixel_precision_bits": d.sub_pixel_precision_bits,
                    "viewport_sub_pixel_bits": d.viewport_sub_pixel_bits,
                    "max_image_dimension_2d": d.max_image_dimension_2d,
                    "max_viewport_dimensions": d.max_viewport_dimensions,
                    "device_local_heap_bytes": d.device_local_heap_bytes,
                    "max_memory_allocation_size": d.max_memory_allocation_size,
                    "max_push_constants_size": d.max_push_constants_size,
                    "shader_float64": d.shader_float64,
                    "ray_query": d.ray_query,
                    "shadow_rays": if casts_ray_queries(d, options.ray_queries) { "ray queries" } else { "shader walk" },
                    "unusable": d.unusable,
                })
            })
            .collect();
        let chosen_json = match &chosen {
            Ok(i) => serde_json::json!(i),
            Err(_) => serde_json::Value::Null,
        };
        println!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({ "devices": list, "chosen": chosen_json }))
                .expect("serialisable")
        );
        return chosen.map(|_| ()).map_err(|e| CliError::Failure(anyhow::anyhow!(e)));
    }
    let gib = |b: u64| b as f64 / (1u64 << 30) as f64;
    for d in &devices {
        let mark = if chosen.as_ref().is_ok_and(|c| *c == d.index) { "*" } else { " " };
        println!(
            "{mark} {}: {} [{}], Vulkan {}.{}.{}",
            d.index,
            d.name,
            d.type_name(),
            d.api_version.0,
            d.api_version.1,
            d.api_version.2
        );
        println!("      driver: {} {}", d.driver_name, d.driver_info);
        println!(
            "      subPixelPrecisionBits {}, viewportSubPixelBits {}, maxImageDimension2D {}, maxViewportDimensions {}x{}",
            d.sub_pixel_precision_bits,
            d.viewport_sub_pixel_bits,
            d.max_image_dimension_2d,
            d.max_viewport_dimensions[0],
            d.max_viewport_dimensions[1]
        );
        println!(
            "      device-local heap {:.2} GiB, maxMemoryAllocationSize {:.2} GiB, maxPushConstantsSize {} B",
            gib(d.device_local_heap_bytes),
            gib(d.max_memory_allocation_size),
            d.max_push_constants_size
        );
        println!(
            "      shaderFloat64 {} (fragment barycentrics in {})",
            d.shader_float64,
            if d.shader_float64 { "f64" } else { "f32" }
        );
        println!(
            "      ray queries (VK_KHR_ray_query + acceleration structures): {}; shadow rays {}",
            if d.ray_query { "yes" } else { "no" },
            if casts_ray_queries(d, options.ray_queries) {
                "by ray queries"
            } else {
                "by the fragment shader's walk of the scene's BVH"
            }
        );
        if let Some(why) = &d.unusable {
            println!("      not usable: {why}");
        }
    }
    match chosen {
        Ok(i) => println!("chosen: device {i} (* above)"),
        Err(e) => return Err(CliError::Failure(anyhow::anyhow!(e))),
    }
    Ok(())
}
