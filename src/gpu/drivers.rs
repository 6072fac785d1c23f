//! Which installed Vulkan drivers the loader opens. The loader opens every driver its manifests list before it can
//! enumerate a device, and Debian's `mesa-vulkan-drivers` installs four: Intel's two and AMD's, which need a DRM
//! render node (`/dev/dri/renderD*`), and lavapipe. On a machine without such a node (a CI runner, a container, a
//! cloud VM without a GPU) the three hardware drivers find nothing, yet opening them is about a quarter of the
//! instance phase (docs/platform.md, "The instance phase"). [`skip_mesa_drivers_without_render_node`] tells the
//! loader to skip Mesa's DRM drivers there, through its own `VK_LOADER_DRIVERS_DISABLE` (Vulkan loader 1.3.234 and
//! later; older loaders ignore it), unless the user chose drivers with any of the loader's variables. A machine with
//! a render node, or another vendor's driver (NVIDIA's opens `/dev/nvidia*`), is left as it is.

/// The manifest files of Mesa's Vulkan drivers that drive a GPU through a DRM render node (globs on the manifest's
/// file name, as the loader matches them). lavapipe (`lvp_icd`) and drivers that use other devices are not here.
pub const MESA_DRM_DRIVERS: &str = "intel_icd.*,intel_hasvk_icd.*,radeon_icd.*,nouveau_icd.*,freedreno_icd.*,\
                                    broadcom_icd.*,panfrost_icd.*,asahi_icd.*,powervr_mesa_icd.*,virtio_icd.*";

/// The loader's variables that choose drivers: where the user set any of them, sunshade sets none.
pub const LOADER_DRIVER_VARIABLES: [&str; 5] = [
    "VK_DRIVER_FILES",
    "VK_ICD_FILENAMES",
    "VK_ADD_DRIVER_FILES",
    "VK_LOADER_DRIVERS_SELECT",
    "VK_LOADER_DRIVERS_DISABLE",
];

/// Whether the drivers of [`MESA_DRM_DRIVERS`] should be skipped: no loader variable set (`var` reads one) and no
/// render node among the entries of `/dev/dri` (`dri`: their file names; `None` where the folder does not exist).
pub fn should_skip(var: impl Fn(&str) -> bool, dri: Option<Vec<String>>) -> bool {
    if LOADER_DRIVER_VARIABLES.iter().any(|v| var(v)) {
        return false;
    }
    !dri.unwrap_or_default().iter().any(|name| name.starts_with("renderD"))
}

/// Sets `VK_LOADER_DRIVERS_DISABLE` to [`MESA_DRM_DRIVERS`] where [`should_skip`] says so. Call it first thing in a
/// process, before any thread starts and before the first Vulkan instance (the CLI's `main` does; a library user
/// may): the environment is the process's, and its children inherit the choice.
pub fn skip_mesa_drivers_without_render_node() {
    let dri = std::fs::read_dir("/dev/dri")
        .ok()
        .map(|entries| entries.filter_map(|e| e.ok()).map(|e| e.file_name().to_string_lossy().into_owned()).collect());
    if should_skip(|v| std::env::var_os(v).is_some(), dri) {
        std::env::set_var("VK_LOADER_DRIVERS_DISABLE", MESA_DRM_DRIVERS);
    }
}

/// Whether a message the loader sends the validation messenger is its notice that it skipped a driver as sunshade
/// asked (not a validation message: the messenger hears the loader too while the instance is made): the variable
/// holds sunshade's own value, set by this process or inherited from the sunshade process that started it.
pub fn is_own_skip_notice(message: &str) -> bool {
    is_skip_notice(message) && std::env::var("VK_LOADER_DRIVERS_DISABLE").is_ok_and(|v| v == MESA_DRM_DRIVERS)
}

/// The loader's notice for a driver left out by `VK_LOADER_DRIVERS_DISABLE` (loader 1.3.239's wording).
fn is_skip_notice(message: &str) -> bool {
    message.starts_with("Driver \"")
        && message.ends_with("ignored because it was disabled by env var 'VK_LOADER_DRIVERS_DISABLE'")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drivers_are_skipped_only_without_a_render_node_and_without_the_users_choice() {
        let none = |_: &str| false;
        assert!(should_skip(none, None));
        assert!(should_skip(none, Some(vec!["card0".into()])));
        assert!(!should_skip(none, Some(vec!["card0".into(), "renderD128".into()])));
        for v in LOADER_DRIVER_VARIABLES {
            assert!(!should_skip(|k: &str| k == v, None), "{v}");
        }
        // lavapipe is never among them.
        assert!(!MESA_DRM_DRIVERS.contains("lvp"));
        assert!(is_skip_notice(
            "Driver \"intel_icd.x86_64.json\" ignored because it was disabled by env var 'VK_LOADER_DRIVERS_DISABLE'"
        ));
        assert!(!is_skip_notice("Validation Error: [ VUID-x ] ... disabled by env var 'VK_LOADER_DRIVERS_DISABLE'"));
    }
}
