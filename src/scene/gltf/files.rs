//! Reading the files a scene names, as untrusted input: only regular files, only inside the scene's folder (unless
//! the user widens it), and never more bytes than the file has or the caller needs.
//!
//! - **Confinement.** A relative URI is joined to the scene's folder and canonicalized (symbolic links and `..`
//!   resolved); the result must lie inside the canonical asset root: the scene's folder by default,
//!   [`UriScope::Folder`] to name another, [`UriScope::Anywhere`] to lift the rule. Absolute paths are refused
//!   unless the scope is `Anywhere`.
//! - **Regular files only.** The file type is checked on the path before it is opened (opening a FIFO for reading
//!   would block), and again on the opened handle (the path could have been swapped in between). The open is
//!   non-blocking on Unix for the same reason.
//! - **Bounded reads.** The size is checked first against what the caller needs (a buffer's `byteLength`), then
//!   exactly that many bytes are read, so a file that grows while it is read, or a declared size larger than the
//!   file, cannot make sunshade allocate or read more.
//!
//! Not covered: a folder an attacker can write to while sunshade reads it (a path swapped between canonicalization
//! and open could still point elsewhere); sunshade is not a sandbox.

use std::fs::{self, File, Metadata};
use std::io::Read;
use std::path::{Path, PathBuf};

/// The largest single file sunshade reads [bytes]: 4 GiB, the most a GLB container can address.
pub const MAX_FILE_BYTES: u64 = 1 << 32;

/// Where the files a scene names may be.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum UriScope {
    /// Inside the scene file's folder (the default).
    #[default]
    SceneFolder,
    /// Inside this folder (`--asset-root DIR`).
    Folder(PathBuf),
    /// Anywhere the user can read (`--allow-outside-uris`); absolute paths too.
    Anywhere,
}

/// Resolves and reads the files of one scene.
pub struct AssetFiles {
    /// The scene file's folder, where relative URIs start.
    base: PathBuf,
    /// The canonical folder every file must lie in; `None` for [`UriScope::Anywhere`].
    root: Option<PathBuf>,
}

impl AssetFiles {
    pub fn new(scene_path: &Path, scope: &UriScope) -> Result<Self, String> {
        let base = match scene_path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let canonical = |dir: &Path| {
            fs::canonicalize(dir).map_err(|e| format!("cannot resolve the asset folder '{}': {e}", dir.display()))
        };
        let root = match scope {
            UriScope::SceneFolder => Some(canonical(&base)?),
            UriScope::Folder(dir) => Some(canonical(dir)?),
            UriScope::Anywhere => None,
        };
        Ok(Self { base, root })
    }

    /// The first `needed` bytes of the file a percent-decoded relative URI names. `uri` is the URI as written, for
    /// messages.
    pub fn read(&self, relative: &str, uri: &str, needed: Option<u64>) -> Result<Vec<u8>, String> {
        let path = self.confined_path(relative, uri)?;
        read_regular_file(&path, needed).map_err(|e| format!("'{uri}': {e}"))
    }

    /// The whole file a percent-decoded relative URI names, refused before reading when it holds more than
    /// `at_most` bytes (a table of known size: a larger file is not read into memory to be refused).
    pub fn read_at_most(&self, relative: &str, uri: &str, at_most: u64) -> Result<Vec<u8>, String> {
        let path = self.confined_path(relative, uri)?;
        read_regular_file_at_most(&path, at_most).map_err(|e| format!("'{uri}': {e}"))
    }

    /// The canonical path of the file a percent-decoded relative URI names, checked against the asset folder.
    fn confined_path(&self, relative: &str, uri: &str) -> Result<std::path::PathBuf, String> {
        if relative.contains('\0') {
            return Err(format!("URI '{uri}' contains a NUL byte"));
        }
        let path = Path::new(relative);
        if path.is_absolute() && self.root.is_some() {
            return Err(format!(
                "URI '{uri}' is an absolute path; only files inside the scene's folder are read \
                 (--asset-root DIR or --allow-outside-uris to allow it)"
            ));
        }
        let joined = self.base.join(path);
        let canonical = fs::canonicalize(&joined).map_err(|e| format!("cannot read '{uri}': {e}"))?;
        if let Some(root) = &self.root {
            if !canonical.starts_with(root) {
                return Err(format!(
                    "URI '{uri}' resolves to '{}', outside the asset folder '{}' \
                     (--asset-root DIR or --allow-outside-uris to allow it)",
                    canonical.display(),
                    root.display()
                ));
            }
        }
        Ok(canonical)
    }
}

/// Reads a whole regular file of at most `at_most` bytes; a larger one is refused from its size, unread.
pub fn read_regular_file_at_most(path: &Path, at_most: u64) -> Result<Vec<u8>, String> {
    let size = fs::metadata(path).map_err(|e| e.to_string())?.len();
    if size > at_most {
        return Err(format!("the file holds {size} bytes, more than the {at_most} expected"));
    }
    // Exactly the bytes the size said: a file that grows meanwhile is not read further.
    read_regular_file(path, Some(size))
}

/// Reads a regular file: all of it (`needed` = `None`, at most [`MAX_FILE_BYTES`]) or its first `needed` bytes,
/// refusing FIFOs, devices, sockets and folders before opening them. Errors do not name the path (the caller does).
pub fn read_regular_file(path: &Path, needed: Option<u64>) -> Result<Vec<u8>, String> {
    let before = fs::metadata(path).map_err(|e| e.to_string())?;
    check_regular(&before)?;
    let file = open_nonblocking(path).map_err(|e| e.to_string())?;
    let after = file.metadata().map_err(|e| e.to_string())?;
    check_regular(&after)?;
    let size = after.len();
    let want = match needed {
        Some(n) if n > size => return Err(format!("the file holds {size} bytes, fewer than the {n} declared")),
        Some(n) => n,
        None => size,
    };
    if want > MAX_FILE_BYTES {
        return Err(format!("{want} bytes is more than sunshade reads from one file ({MAX_FILE_BYTES})"));
    }
    let mut data = Vec::with_capacity(want as usize);
    file.take(want).read_to_end(&mut data).map_err(|e| e.to_string())?;
    if (data.len() as u64) < want {
        return Err(format!("the file ended after {} of {want} bytes", data.len()));
    }
    Ok(data)
}

fn check_regular(m: &Metadata) -> Result<(), String> {
    if m.is_file() {
        return Ok(());
    }
    let kind = file_kind(m);
    Err(format!("is {kind}, not a regular file"))
}

#[cfg(unix)]
fn file_kind(m: &Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = m.file_type();
    if t.is_dir() {
        "a directory"
    } else if t.is_fifo() {
        "a FIFO"
    } else if t.is_char_device() || t.is_block_device() {
        "a device"
    } else if t.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    }
}

#[cfg(not(unix))]
fn file_kind(m: &Metadata) -> &'static str {
    if m.is_dir() {
        "a directory"
    } else {
        "a special file"
    }
}

#[cfg(unix)]
fn open_nonblocking(path: &Path) -> std::io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt;
    fs::OpenOptions::new().read(true).custom_flags(libc::O_NONBLOCK).open(path)
}

#[cfg(not(unix))]
fn open_nonblocking(path: &Path) -> std::io::Result<File> {
    File::open(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("sunshade-files-{}-{tag}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(d.join("scene/sub")).unwrap();
        fs::write(d.join("scene/a.bin"), [1u8, 2, 3, 4]).unwrap();
        fs::write(d.join("scene/sub/b.bin"), [5u8; 8]).unwrap();
        fs::write(d.join("secret.bin"), [9u8; 4]).unwrap();
        d
    }

    #[test]
    fn reads_inside_and_refuses_outside() {
        let d = temp("confine");
        let files = AssetFiles::new(&d.join("scene/s.gltf"), &UriScope::SceneFolder).unwrap();
        assert_eq!(files.read("a.bin", "a.bin", Some(2)).unwrap(), [1, 2]);
        assert_eq!(files.read("sub/../a.bin", "sub/../a.bin", Some(4)).unwrap(), [1, 2, 3, 4]);
        assert_eq!(files.read("sub/b.bin", "sub/b.bin", Some(8)).unwrap(), [5; 8]);
        assert!(files
            .read("../secret.bin", "../secret.bin", Some(4))
            .unwrap_err()
            .contains("outside the asset folder"));
        let abs = d.join("secret.bin");
        let abs = abs.to_str().unwrap();
        assert!(files.read(abs, abs, Some(4)).unwrap_err().contains("absolute path"));
        assert!(files.read("a.bin", "a.bin", Some(5)).unwrap_err().contains("fewer than the 5 declared"));
        assert!(files.read("sub", "sub", Some(0)).unwrap_err().contains("a directory"));
        assert!(files.read("missing.bin", "missing.bin", Some(0)).unwrap_err().contains("missing.bin"));

        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(d.join("secret.bin"), d.join("scene/link.bin")).unwrap();
            assert!(files.read("link.bin", "link.bin", Some(4)).unwrap_err().contains("outside the asset folder"));
        }
        let wide = AssetFiles::new(&d.join("scene/s.gltf"), &UriScope::Folder(d.clone())).unwrap();
        assert_eq!(wide.read("../secret.bin", "../secret.bin", Some(4)).unwrap(), [9; 4]);
        let anywhere = AssetFiles::new(&d.join("scene/s.gltf"), &UriScope::Anywhere).unwrap();
        assert_eq!(anywhere.read(abs, abs, Some(4)).unwrap(), [9; 4]);
        fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn special_files_are_refused_before_reading() {
        let err = read_regular_file(Path::new("/dev/zero"), None).unwrap_err();
        assert!(err.contains("a device"), "{err}");
        let d = temp("fifo");
        let fifo = d.join("scene/pipe.bin");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status().map(|s| s.success()).unwrap_or(false);
        assert!(made, "mkfifo failed");
        {
            let err = read_regular_file(&fifo, Some(4)).unwrap_err();
            assert!(err.contains("a FIFO"), "{err}");
        }
        fs::remove_dir_all(&d).unwrap();
    }
}
