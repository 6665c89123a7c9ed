//! The Vulkan pipeline cache, kept between runs in the user's cache folder, so a run
//! does not pay again for pipelines an earlier run built (no cold-start tax where the
//! driver caches compiled pipelines).
//!
//! One file per driver and shader set: `pipelines-v1/VENDOR-DEVICE-DRIVER-UUID-SHADERS.bin`
//! under [`crate::cache::root`] (vendor and device id, driver version, `pipelineCacheUUID`, and
//! the hash of every shader texgeo embeds), so another driver, device or texgeo build
//! never reads it. The file is `texgeo pipeline cache 1\n`, the data's length and FNV-1a
//! hash (u64 little-endian each), then the data `vkGetPipelineCacheData` gave. A file that
//! is short, has another length or hash (torn, corrupt), or whose Vulkan header (§ "Pipeline
//! Cache" of the spec: length, version 1, vendor, device, UUID) does not match the device
//! is ignored, and the cache starts empty. It is saved when the device is dropped, only if
//! the driver's data changed, atomically ([`crate::output`]: a temporary file renamed into
//! place), so concurrent runs each leave one complete file. Failures to read or write it
//! change nothing but the time.
//!
//! `TEXGEO_CACHE=off` (or `0`) turns it off (tests that must start cold).

use std::path::{Path, PathBuf};

use ash::vk;

const MAGIC: &[u8] = b"texgeo pipeline cache 1\n";
/// Folder of the entries; bumped if the file layout changes.
const KIND: &str = "pipelines-v1";

fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3))
}

/// The identity of a device's pipeline cache data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Identity {
    pub vendor: u32,
    pub device: u32,
    pub driver: u32,
    pub uuid: [u8; 16],
}

impl Identity {
    pub fn of(props: &vk::PhysicalDeviceProperties) -> Identity {
        Identity {
            vendor: props.vendor_id,
            device: props.device_id,
            driver: props.driver_version,
            uuid: props.pipeline_cache_uuid,
        }
    }

    fn file_name(&self) -> String {
        let uuid: String = self.uuid.iter().map(|b| format!("{b:02x}")).collect();
        format!(
            "{:04x}-{:04x}-{:x}-{uuid}-{:016x}.bin",
            self.vendor,
            self.device,
            self.driver,
            super::shaders::SPIRV_HASH
        )
    }

    /// Whether `data` starts with a Vulkan pipeline cache header of this device.
    fn matches(&self, data: &[u8]) -> bool {
        let word =
            |i: usize| u32::from_le_bytes([data[4 * i], data[4 * i + 1], data[4 * i + 2], data[4 * i + 3]]);
        data.len() >= 32
            && word(0) >= 32
            && word(0) as usize <= data.len()
            && word(1) == vk::PipelineCacheHeaderVersion::ONE.as_raw() as u32
            && word(2) == self.vendor
            && word(3) == self.device
            && data[16..32] == self.uuid
    }
}

/// Encodes a cache file.
fn encode(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(MAGIC.len() + 16 + data.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&(data.len() as u64).to_le_bytes());
    out.extend_from_slice(&fnv1a(data).to_le_bytes());
    out.extend_from_slice(data);
    out
}

/// The driver data of a cache file, if it is whole and made for `id`.
fn decode<'a>(file: &'a [u8], id: &Identity) -> Option<&'a [u8]> {
    let rest = file.strip_prefix(MAGIC)?;
    let (len, rest) = rest.split_first_chunk::<8>()?;
    let (hash, data) = rest.split_first_chunk::<8>()?;
    (u64::from_le_bytes(*len) == data.len() as u64
        && u64::from_le_bytes(*hash) == fnv1a(data)
        && id.matches(data))
    .then_some(data)
}

/// A device's `VkPipelineCache` and the file it came from and goes back to.
pub(crate) struct PipelineCache {
    pub raw: vk::PipelineCache,
    path: Option<PathBuf>,
    id: Identity,
    /// Hash of the data loaded, to skip saving what did not change.
    loaded: Option<u64>,
}

impl PipelineCache {
    /// Creates the device's cache, from its file when there is a valid one. Never fails:
    /// without a usable file (or when even an empty cache cannot be made) pipelines are
    /// built without one.
    pub fn open(raw: &ash::Device, id: Identity) -> PipelineCache {
        let path = crate::cache::root().map(|r| r.join(KIND).join(id.file_name()));
        PipelineCache::open_at(raw, id, path)
    }

    pub fn open_at(raw: &ash::Device, id: Identity, path: Option<PathBuf>) -> PipelineCache {
        let file = path.as_deref().and_then(|p| std::fs::read(p).ok());
        let data = file.as_deref().and_then(|f| decode(f, &id));
        let create = |initial: &[u8]| {
            let info = vk::PipelineCacheCreateInfo::default().initial_data(initial);
            // SAFETY: valid device; `initial` was checked against the device's header.
            unsafe { raw.create_pipeline_cache(&info, None) }.ok()
        };
        let (cache, loaded) = match data.and_then(|d| create(d).map(|c| (c, fnv1a(d)))) {
            Some((c, hash)) => (c, Some(hash)),
            None => (create(&[]).unwrap_or(vk::PipelineCache::null()), None),
        };
        PipelineCache { raw: cache, path, id, loaded }
    }

    /// Writes the driver's data back if it changed, then destroys the cache.
    pub fn save_and_destroy(&mut self, raw: &ash::Device) {
        if self.raw == vk::PipelineCache::null() {
            return;
        }
        // SAFETY: valid device and cache; no pipeline is being created (the device is
        // being dropped).
        let data = unsafe { raw.get_pipeline_cache_data(self.raw) }.ok();
        if let (Some(path), Some(data)) = (&self.path, data)
            && self.id.matches(&data)
            && self.loaded != Some(fnv1a(&data))
        {
            save(path, &data);
        }
        // SAFETY: as above; the handle is not used again.
        unsafe { raw.destroy_pipeline_cache(self.raw, None) };
        self.raw = vk::PipelineCache::null();
    }
}

fn save(path: &Path, data: &[u8]) {
    if let Some(dir) = path.parent()
        && std::fs::create_dir_all(dir).is_ok()
    {
        let _ = crate::output::write_bytes(path, &encode(data));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn id() -> Identity {
        Identity { vendor: 0x10005, device: 0, driver: 1, uuid: [7; 16] }
    }

    fn header(id: &Identity, extra: usize) -> Vec<u8> {
        let mut d = Vec::new();
        for w in [32u32, 1, id.vendor, id.device] {
            d.extend_from_slice(&w.to_le_bytes());
        }
        d.extend_from_slice(&id.uuid);
        d.extend(std::iter::repeat_n(0xab, extra));
        d
    }

    #[test]
    fn only_whole_files_of_the_same_device_are_read() {
        let data = header(&id(), 100);
        let file = encode(&data);
        assert_eq!(decode(&file, &id()), Some(&data[..]));
        // Torn, corrupt, another device or driver UUID, another format: ignored.
        assert_eq!(decode(&file[..file.len() - 1], &id()), None);
        let mut flipped = file.clone();
        *flipped.last_mut().unwrap() ^= 1;
        assert_eq!(decode(&flipped, &id()), None);
        assert_eq!(decode(&file, &Identity { device: 9, ..id() }), None);
        assert_eq!(decode(&file, &Identity { uuid: [8; 16], ..id() }), None);
        assert_eq!(decode(b"texgeo pipeline cache 1\n", &id()), None);
        assert_eq!(decode(b"", &id()), None);
        let mut bad_version = header(&id(), 0);
        bad_version[4] = 2;
        assert_eq!(decode(&encode(&bad_version), &id()), None);
        // The file name changes with the driver and device.
        assert_ne!(id().file_name(), Identity { driver: 2, ..id() }.file_name());
    }
}
