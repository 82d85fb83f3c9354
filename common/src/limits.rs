//! The limits on every quantity a user controls — image size, primitive counts,
//! file sizes, value ranges — and the memory a job needs. Each limit is one
//! constant here; scene files, `--set` and `--size` are all checked against it,
//! so that a count from a file cannot slip past a cap that `--set` has.
//! Device limits (maxImageDimension2D, maxStorageBufferRange, GL_MAX_TEXTURE_SIZE...)
//! are checked by each app against its own device, after these.

use crate::error::bad_input;
use crate::gpu::layout::{GpuBvhNode, GpuBvhPrim, GpuSphere, GpuTriangle};

/// Width or height: twice the largest maxImageDimension2D / GL_MAX_TEXTURE_SIZE
/// any device reports (32768), so no device could render beyond it.
pub const MAX_IMAGE_DIMENSION: u32 = 65536;

/// Storage buffers are bound with a 32-bit range in both APIs
/// (maxStorageBufferRange and GL_MAX_SHADER_STORAGE_BLOCK_SIZE are at most
/// 2^32 - 1), so a scene whose buffer is larger cannot be rendered anywhere.
pub const MAX_STORAGE_BUFFER_BYTES: u64 = u32::MAX as u64;

/// Spheres (including `extra_spheres`): what one storage buffer can hold
/// (134 million); each device's own limit is usually lower and checked by the app.
pub const MAX_SPHERES: usize = (MAX_STORAGE_BUFFER_BYTES as usize) / size_of::<GpuSphere>();

/// Triangles (inline, quads and meshes together): what one storage buffer can hold (44 million).
pub const MAX_TRIANGLES: usize = (MAX_STORAGE_BUFFER_BYTES as usize) / size_of::<GpuTriangle>();

/// Primitives a BVH can hold: its n leaf primitives (`GpuBvhPrim`) and its
/// fewer than n interior nodes must each fit the same 32-bit range.
pub const MAX_BVH_PRIMITIVES: usize = (MAX_STORAGE_BUFFER_BYTES as usize)
    / if size_of::<GpuBvhNode>() > size_of::<GpuBvhPrim>() {
        size_of::<GpuBvhNode>()
    } else {
        size_of::<GpuBvhPrim>()
    };
// A leaf's first primitive must fit its child reference's bits.
const _: () = assert!(MAX_BVH_PRIMITIVES <= crate::gpu::layout::child_ref::MAX_PRIMS);

/// Point lights: each adds a shadow ray at every hit; more than this is a mistake, not a scene.
pub const MAX_LIGHTS: usize = 4096;

/// Materials: referenced by a 32-bit index, but a scene needs a handful.
pub const MAX_MATERIALS: usize = 65536;

/// `extra_spheres.count` (file or `--set extra_spheres`): the study's largest is
/// 10,000; this is enough to exceed any device's storage-buffer limit on purpose.
pub const MAX_EXTRA_SPHERES: u32 = 10_000_000;

/// `tessellation` per direction (file or `--set`): 400 x 400 quads per patch is
/// 10 million triangles for the 32-patch teapot.
pub const MAX_TESSELLATION: u32 = 400;

/// `render.max_depth`: the shader's generic ray stack holds this + 1.
pub const MAX_DEPTH: u32 = 16;

/// Scene files are hand-written TOML; 16 MiB is far beyond any of them, and
/// keeps `--scene /dev/zero`-like inputs from reading until memory runs out.
pub const MAX_SCENE_FILE_BYTES: u64 = 16 << 20;

/// Mesh files (OBJ, .bpt): a 2-million-triangle OBJ is about 150 MB.
pub const MAX_MESH_FILE_BYTES: u64 = 1 << 30;

/// Coordinates, radii and distances, in scene units. The shader squares
/// differences of coordinates in f32 (3.4e38 at most) and treats t above 1e30 as
/// a miss: at 4e18 a sum of three squared differences (12 * 1.6e37 = 1.9e38)
/// stays finite and every hit lies below that horizon.
pub const MAX_COORDINATE: f64 = 4e18;

/// Colour components (ambient, diffuse, specular, light colour, background):
/// products of a light colour, a diffuse colour and a few hundred lights stay finite in f32.
pub const MAX_COLOUR: f64 = 1e6;

/// Index of refraction: `eta^2` of the refraction test stays finite in f32 and
/// far from zero across this range.
pub const MIN_IOR: f64 = 1e-3;
pub const MAX_IOR: f64 = 1e3;

/// Host memory per pixel of a render, upper bound over the three tools: the
/// RGBA32F target (16 B) and its readback (16 B; on a software driver device
/// memory is host memory), the float copy (16 B), the RGB float image (12 B),
/// the 8-bit image and its PNG (3 + 3 B).
pub const HOST_BYTES_PER_PIXEL: u64 = 66;

/// `count` against `max`: the one check for every count, wherever it came from.
/// `what` names the option or field (`--set extra_spheres`, `scene file 'a.toml': extra_spheres.count`).
pub fn check_count(what: &str, count: usize, max: usize) -> anyhow::Result<()> {
    if count > max {
        return Err(bad_input(format!(
            "{what} = {count} is more than the limit of {max}"
        )));
    }
    Ok(())
}

/// Pixels of a `width` x `height` image, in usize without overflow.
pub fn pixel_count(width: u32, height: u32) -> usize {
    // u32 * u32 fits in u64 always; usize is 64-bit on every platform we build for.
    (width as u64 * height as u64) as usize
}

/// Refuses an image larger than `MAX_IMAGE_DIMENSION` per side, or one whose
/// buffers need more host memory than the machine has available now.
/// Checked before any scene is loaded or device opened, for every tool.
pub fn check_image_size(width: u32, height: u32) -> anyhow::Result<()> {
    if width == 0 || height == 0 || width > MAX_IMAGE_DIMENSION || height > MAX_IMAGE_DIMENSION {
        return Err(bad_input(format!(
            "--size {width}x{height}: width and height must be from 1 to {MAX_IMAGE_DIMENSION}"
        )));
    }
    let need = (width as u64)
        .checked_mul(height as u64)
        .and_then(|p| p.checked_mul(HOST_BYTES_PER_PIXEL))
        .unwrap_or(u64::MAX);
    if let Some(available) = available_memory() {
        if need > available {
            return Err(bad_input(format!(
                "--size {width}x{height} needs about {} of memory for its image buffers, more than the {} available",
                gib(need),
                gib(available)
            )));
        }
    }
    Ok(())
}

/// Refuses a scene buffer no device could bind (more than 2^32 - 1 bytes).
/// `what` names the buffer's source, e.g. "the scene's triangles".
pub fn check_storage_bytes(what: &str, count: usize, element_bytes: usize) -> anyhow::Result<()> {
    let bytes = (count as u64).saturating_mul(element_bytes as u64);
    if bytes > MAX_STORAGE_BUFFER_BYTES {
        return Err(bad_input(format!(
            "{what} need {bytes} bytes, more than any device can bind in one storage buffer ({MAX_STORAGE_BUFFER_BYTES})"
        )));
    }
    Ok(())
}

/// The largest storage buffer a run may bind, and whose limit it is. Scenes
/// are checked against it while they are loaded, before a tessellation or a
/// list of spheres is made, so that a scene no device could take costs no work;
/// each app passes its device's own figure, the rest `ANY`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StorageLimit {
    pub bytes: u64,
    /// Whose limit, as a message names it: "this device's maxStorageBufferRange".
    pub name: &'static str,
    /// The texels a buffer texture may hold (OpenGL's
    /// GL_MAX_TEXTURE_BUFFER_SIZE): 0 where the app reads none.
    pub texel_buffer: u64,
}

impl StorageLimit {
    /// What any device could bind: where no device is known (the reference, tools).
    pub const ANY: StorageLimit = StorageLimit {
        bytes: MAX_STORAGE_BUFFER_BYTES,
        name: "twinray's 4 GiB storage-buffer limit",
        texel_buffer: 0,
    };

    /// Refuses `count` elements of `element_bytes` in the scene's `buffer`
    /// buffer when they would not fit, in the sentence of the apps' upload check.
    /// `what` names the source of the count (a field, `--set KEY`).
    pub fn check(
        &self,
        what: &str,
        buffer: &str,
        count: usize,
        element_bytes: usize,
    ) -> anyhow::Result<()> {
        let bytes = (count as u64).saturating_mul(element_bytes as u64);
        if bytes > self.bytes {
            return Err(bad_input(format!(
                "{what}: the scene's {buffer} buffer would need {bytes} bytes for {count} {buffer}, more than {} ({} bytes); use fewer primitives",
                self.name, self.bytes
            )));
        }
        Ok(())
    }
}

/// MemAvailable from /proc/meminfo (Linux); None where it cannot be read, in
/// which case only the fixed limits apply.
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// Bytes as "12.3 GiB" for messages.
pub fn gib(bytes: u64) -> String {
    format!("{:.1} GiB", bytes as f64 / (1u64 << 30) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_at_and_beyond_the_limit() {
        assert!(check_image_size(16, 16).is_ok());
        assert!(check_image_size(0, 16).is_err());
        assert!(check_image_size(MAX_IMAGE_DIMENSION + 1, 1).is_err());
        // 2^32 pixels need 283 GB: refused, without overflow, wherever memory is smaller.
        if available_memory().is_some_and(|a| a < 65536 * 65536 * HOST_BYTES_PER_PIXEL) {
            assert!(check_image_size(65536, 65536).is_err());
        }
        assert_eq!(pixel_count(65536, 65536), 1usize << 32);
    }

    #[test]
    fn counts() {
        assert!(check_count("x", 3, 3).is_ok());
        let e = check_count("--set extra_spheres", 4, 3).unwrap_err();
        assert!(e.to_string().contains("--set extra_spheres = 4"));
        assert!(check_storage_bytes("t", MAX_TRIANGLES, size_of::<GpuTriangle>()).is_ok());
        assert!(check_storage_bytes("t", MAX_TRIANGLES + 1, size_of::<GpuTriangle>()).is_err());
    }

    #[test]
    fn a_storage_limit_names_itself_and_the_buffer() {
        let t = size_of::<GpuTriangle>();
        assert!(StorageLimit::ANY
            .check("x", "triangles", MAX_TRIANGLES, t)
            .is_ok());
        assert!(StorageLimit::ANY
            .check("x", "triangles", MAX_TRIANGLES + 1, t)
            .is_err());
        let small = StorageLimit {
            bytes: 1000,
            name: "a test device's limit",
            texel_buffer: 0,
        };
        let e = small
            .check("--set tessellation", "triangles", 11, 96)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("--set tessellation") && e.contains("1056 bytes"),
            "{e}"
        );
        assert!(e.contains("a test device's limit (1000 bytes)"), "{e}");
    }
}
