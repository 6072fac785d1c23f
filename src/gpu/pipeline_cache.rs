//! A `VkPipelineCache` kept on disk, so that a second process creates its pipelines from the first one's.
//!
//! One file per device, driver and shader build: `pipelines-VENDOR-DEVICE-DRIVER-UUID-SHADERS.bin` in the cache
//! folder ([`default_dir`]), where SHADERS is a hash of the SPIR-V of both stages. The driver validates the
//! data's header too; data it refuses is dropped and the cache starts empty. Writes are atomic (temporary file,
//! then rename), so two processes writing at once leave one whole, valid file: the last one's.

use std::path::{Path, PathBuf};

use ash::vk;

use super::device_info::DeviceInfo;
use super::error::{GpuError, VkContext};

/// The folder for caches: `$SUNSHADE_CACHE_DIR`, else `$XDG_CACHE_HOME/sunshade`, else `~/.cache/sunshade`.
pub fn default_dir() -> Option<PathBuf> {
    let var = |k: &str| std::env::var_os(k).filter(|v| !v.is_empty()).map(PathBuf::from);
    var("SUNSHADE_CACHE_DIR")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("sunshade")))
        .or_else(|| var("HOME").map(|h| h.join(".cache/sunshade")))
}

/// FNV-1a (64 bit) of the SPIR-V words: identifies the shader build in the file name.
pub fn shader_hash(modules: &[&[u32]]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for m in modules {
        for w in m.iter() {
            for b in w.to_le_bytes() {
                h = (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
            }
        }
    }
    h
}

/// The cache file's name for a device and shader build.
pub fn file_name(info: &DeviceInfo, shaders: u64) -> String {
    let uuid: String = info.pipeline_cache_uuid.iter().map(|b| format!("{b:02x}")).collect();
    format!(
        "pipelines-{:04x}-{:04x}-{:08x}-{uuid}-{shaders:016x}.bin",
        info.vendor_id, info.device_id, info.driver_version
    )
}

/// A pipeline cache and where it is saved.
pub struct DiskPipelineCache {
    pub cache: vk::PipelineCache,
    path: Option<PathBuf>,
    /// Bytes loaded from the file at creation (0: none or refused).
    pub loaded_bytes: usize,
    /// The data as loaded, so that an unchanged cache is not written again.
    loaded: Vec<u8>,
}

impl DiskPipelineCache {
    /// Creates the cache from `dir/file_name`'s data when it is there; `dir = None`: an in-memory cache only.
    ///
    /// # Safety
    /// `device` must be a valid device; the cache must be destroyed with it ([`Self::destroy`]).
    pub unsafe fn open(device: &ash::Device, dir: Option<&Path>, file_name: &str) -> Result<Self, GpuError> {
        let path = dir.map(|d| d.join(file_name));
        let data = path.as_deref().and_then(|p| std::fs::read(p).ok()).unwrap_or_default();
        let create = |initial: &[u8]| {
            device
                .create_pipeline_cache(&vk::PipelineCacheCreateInfo::default().initial_data(initial), None)
                .vk("vkCreatePipelineCache")
        };
        let (cache, loaded) = match create(&data) {
            Ok(c) => (c, data),
            // Data the driver refuses (another driver's, truncated): start empty.
            Err(_) if !data.is_empty() => (create(&[])?, Vec::new()),
            Err(e) => return Err(e),
        };
        Ok(Self { cache, path, loaded_bytes: loaded.len(), loaded })
    }

    /// Writes the cache's data to its file (atomically). A cache folder that cannot be written is not an error
    /// of the render: the message is returned for the caller to print as a warning.
    ///
    /// # Safety
    /// `device` must be the device the cache was created with.
    pub unsafe fn save(&self, device: &ash::Device) -> Result<(), String> {
        let Some(path) = &self.path else { return Ok(()) };
        let data = device.get_pipeline_cache_data(self.cache).map_err(|e| format!("vkGetPipelineCacheData: {e}"))?;
        if data == self.loaded {
            return Ok(());
        }
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        crate::film::write_atomically(path, |w| std::io::Write::write_all(w, &data))
            .map_err(|e| format!("{}: {e}", path.display()))
    }

    /// # Safety
    /// `device` must be the device the cache was created with, idle with respect to it.
    pub unsafe fn destroy(&mut self, device: &ash::Device) {
        device.destroy_pipeline_cache(self.cache, None);
        self.cache = vk::PipelineCache::null();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_name_changes_with_shaders_and_driver() {
        let a: &[u32] = &[0x0723_0203, 1, 2];
        let b: &[u32] = &[0x0723_0203, 1, 3];
        assert_ne!(shader_hash(&[a]), shader_hash(&[b]));
        assert_ne!(shader_hash(&[a, b]), shader_hash(&[b, a]));
        assert_eq!(shader_hash(&[a]), shader_hash(&[a]));
    }
}
