//! The Vulkan pipeline cache, kept between runs in the user's cache folder, so a run
//! does not pay again for pipelines an earlier run built (no cold-start tax where the
//! driver caches compiled pipelines).
//!
//! One entry of the cache store [`crate::cache::Store`] (kind `pipelines-v2`) per driver and
//! shader set: its key hashes the vendor and device id, the driver version, the
//! `pipelineCacheUUID` and every shader texgeo embeds (path and SPIR-V), so another driver,
//! device or texgeo build never reads it. The store keeps entries whole and checked (a torn
//! or corrupt file reads as absent); on top of that, data whose Vulkan header (§ "Pipeline
//! Cache" of the spec: length, version 1, vendor, device, UUID) does not match the device
//! is ignored, and the cache starts empty. It is saved when the device is dropped, only if
//! the driver's data changed. Failures to read or write it change nothing but the time.
//!
//! `TEXGEO_CACHE=off` (or `0`) turns it off (tests that must start cold).

use ash::vk;

use crate::cache::{Key, KeyHasher, Store};

/// Kind of the store's entries; bumped if what they hold changes.
const KIND: &str = "pipelines-v2";

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

    /// The store key of this device's data for the shaders of this build.
    fn key(&self) -> Key {
        let mut h = KeyHasher::new(KIND);
        for v in [self.vendor, self.device, self.driver] {
            h.u64(u64::from(v));
        }
        h.bytes(&self.uuid);
        for shader in super::shaders::ALL {
            h.bytes(shader.path.as_bytes());
            h.bytes(shader.spirv);
        }
        h.finish()
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

/// A device's `VkPipelineCache` and the file it came from and goes back to.
pub(crate) struct PipelineCache {
    pub raw: vk::PipelineCache,
    store: Option<Store>,
    id: Identity,
    /// Hash of the data loaded, to skip saving what did not change.
    loaded: Option<blake3::Hash>,
}

impl PipelineCache {
    /// Creates the device's cache, from its file when there is a valid one. Never fails:
    /// without a usable file (or when even an empty cache cannot be made) pipelines are
    /// built without one.
    pub fn open(raw: &ash::Device, id: Identity) -> PipelineCache {
        let store = Store::open(KIND);
        let file = store.as_ref().and_then(|s| s.get(&id.key()));
        let data = file.as_deref().filter(|d| id.matches(d));
        let create = |initial: &[u8]| {
            let info = vk::PipelineCacheCreateInfo::default().initial_data(initial);
            // SAFETY: valid device; `initial` was checked against the device's header.
            unsafe { raw.create_pipeline_cache(&info, None) }.ok()
        };
        let (cache, loaded) = match data.and_then(|d| create(d).map(|c| (c, blake3::hash(d)))) {
            Some((c, hash)) => (c, Some(hash)),
            None => (create(&[]).unwrap_or(vk::PipelineCache::null()), None),
        };
        PipelineCache { raw: cache, store, id, loaded }
    }

    /// Writes the driver's data back if it changed, then destroys the cache.
    pub fn save_and_destroy(&mut self, raw: &ash::Device) {
        if self.raw == vk::PipelineCache::null() {
            return;
        }
        // SAFETY: valid device and cache; no pipeline is being created (the device is
        // being dropped).
        let data = unsafe { raw.get_pipeline_cache_data(self.raw) }.ok();
        if let (Some(store), Some(data)) = (&self.store, data)
            && self.id.matches(&data)
            && self.loaded != Some(blake3::hash(&data))
        {
            store.put(&self.id.key(), &data);
        }
        // SAFETY: as above; the handle is not used again.
        unsafe { raw.destroy_pipeline_cache(self.raw, None) };
        self.raw = vk::PipelineCache::null();
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
    fn only_data_of_the_same_device_is_used() {
        let data = header(&id(), 100);
        assert!(id().matches(&data));
        // Another device or driver UUID, another header version, short data: ignored.
        assert!(!Identity { device: 9, ..id() }.matches(&data));
        assert!(!Identity { uuid: [8; 16], ..id() }.matches(&data));
        assert!(!id().matches(&data[..31]));
        assert!(!id().matches(b""));
        let mut bad_version = header(&id(), 0);
        bad_version[4] = 2;
        assert!(!id().matches(&bad_version));
        // The key changes with the driver and device.
        assert_ne!(id().key(), Identity { driver: 2, ..id() }.key());
        assert_ne!(id().key(), Identity { device: 1, ..id() }.key());
    }
}
