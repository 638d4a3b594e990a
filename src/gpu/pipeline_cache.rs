//! The persistent pipeline cache: one `VkPipelineCache` per context, which every pipeline is
//! made through, filled from `$XDG_CACHE_HOME/lookdev/pipelines/` when the context is made and
//! written back when it is destroyed, if pipelines added to it (docs/formats.md#caches).
//!
//! The file is keyed by the device (vendor and device ids, driver version, the driver's
//! `pipelineCacheUUID`) and by this build's shaders, so data from another driver, device or
//! shader build is never handed to the driver; the driver's own header is checked too, before
//! the data reaches it.

use super::shaders;
use crate::cache::{self, Entry};
use ash::vk;
use std::path::PathBuf;

/// Bump when what is stored changes.
const ENTRY: Entry = Entry { kind: "pipeline", version: 1, max_payload: 64 << 20 };

/// The size of Vulkan's pipeline cache header, version one.
const VK_HEADER: usize = 32;

/// The cache, with where its data came from and goes back to.
pub(crate) struct PipelineCache {
    pub(crate) handle: vk::PipelineCache,
    /// None when there is no cache folder.
    path: Option<PathBuf>,
    key: Vec<u8>,
    /// The header the device's data starts with.
    header: [u8; VK_HEADER],
    /// The hash of the data it started from, to skip writing back what is unchanged.
    loaded: Option<[u8; 16]>,
}

/// What the driver's data must start with: Vulkan's header for this device.
fn expected_header(props: &vk::PhysicalDeviceProperties) -> [u8; VK_HEADER] {
    let mut header = [0u8; VK_HEADER];
    header[0..4].copy_from_slice(&(VK_HEADER as u32).to_le_bytes());
    header[4..8].copy_from_slice(&(vk::PipelineCacheHeaderVersion::ONE.as_raw() as u32).to_le_bytes());
    header[8..12].copy_from_slice(&props.vendor_id.to_le_bytes());
    header[12..16].copy_from_slice(&props.device_id.to_le_bytes());
    header[16..32].copy_from_slice(&props.pipeline_cache_uuid);
    header
}

/// Whether `data` starts with the header the device writes: its length field, version, ids
/// and UUID (the header may be longer than version one's; the rest is the driver's).
fn header_matches(data: &[u8], expected: &[u8; VK_HEADER]) -> bool {
    if data.len() < VK_HEADER {
        return false;
    }
    let length = u32::from_le_bytes(data[0..4].try_into().expect("4 bytes")) as usize;
    (VK_HEADER..=data.len()).contains(&length) && data[4..VK_HEADER] == expected[4..]
}

/// The key: the device's header, its driver version, and a hash of every shader in this build.
fn key(props: &vk::PhysicalDeviceProperties) -> Vec<u8> {
    let mut spirv = Vec::new();
    for kernel in shaders::ALL {
        spirv.extend_from_slice(&cache::hash128(kernel.spirv));
    }
    for stage in shaders::STAGES {
        spirv.extend_from_slice(&cache::hash128(stage.spirv));
    }
    let mut key = expected_header(props).to_vec();
    key.extend_from_slice(&props.driver_version.to_le_bytes());
    key.extend_from_slice(&cache::hash128(&spirv));
    key
}

impl PipelineCache {
    /// The context's cache, with the stored data when there is sound data for this device and
    /// build. Without a cache folder, or when the driver refuses the data, it starts empty.
    pub(crate) fn new(device: &ash::Device, props: &vk::PhysicalDeviceProperties) -> crate::Result<PipelineCache> {
        let _timing = crate::timings::phase("pipeline cache load");
        let file =
            format!("{:04x}-{:04x}-{}.bin", props.vendor_id, props.device_id, cache::hex(&props.pipeline_cache_uuid));
        let path = cache::folder("pipelines").map(|folder| folder.join(file));
        let (key, header) = (key(props), expected_header(props));
        let data = path.as_deref().and_then(|path| ENTRY.load(path, &key)).filter(|data| header_matches(data, &header));
        let loaded = data.as_deref().map(cache::hash128);
        crate::timings::note(|| match (&data, &path) {
            (Some(data), Some(path)) => format!("pipeline cache: loaded {} bytes from {}", data.len(), path.display()),
            _ => "pipeline cache: starting empty".to_string(),
        });
        let info = vk::PipelineCacheCreateInfo::default().initial_data(data.as_deref().unwrap_or_default());
        let handle = match unsafe { device.create_pipeline_cache(&info, None) } {
            Ok(handle) => handle,
            // A driver may still refuse data it wrote; then start without it.
            Err(_) if data.is_some() => {
                unsafe { device.create_pipeline_cache(&vk::PipelineCacheCreateInfo::default(), None) }?
            }
            Err(e) => return Err(e.into()),
        };
        Ok(PipelineCache { handle, path, key, header, loaded })
    }

    /// Writes the data back if pipelines changed it, then destroys the cache.
    pub(crate) fn save_and_destroy(&mut self, device: &ash::Device) {
        if self.handle == vk::PipelineCache::null() {
            return;
        }
        if let (Some(path), Ok(data)) = (&self.path, unsafe { device.get_pipeline_cache_data(self.handle) }) {
            let changed = self.loaded != Some(cache::hash128(&data));
            if changed && header_matches(&data, &self.header) {
                let _timing = crate::timings::phase("pipeline cache save");
                ENTRY.store(path, &self.key, &data);
            }
        }
        unsafe { device.destroy_pipeline_cache(self.handle, None) };
        self.handle = vk::PipelineCache::null();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_this_devices_header_is_handed_to_the_driver() {
        let mut props = vk::PhysicalDeviceProperties { vendor_id: 0x10de, device_id: 0x2684, ..Default::default() };
        props.pipeline_cache_uuid = [7; 16];
        let header = expected_header(&props);
        let mut data = header.to_vec();
        data.extend_from_slice(&[1, 2, 3]);
        assert!(header_matches(&data, &header));
        assert!(!header_matches(&data[..31], &header), "truncated");
        for byte in 4..VK_HEADER {
            let mut other = data.clone();
            other[byte] ^= 1;
            assert!(!header_matches(&other, &header), "byte {byte} differs");
        }
        let mut long_header = data.clone();
        long_header[0] = 35;
        assert!(header_matches(&long_header, &header), "a longer header within the data");
        long_header[0] = 36;
        assert!(!header_matches(&long_header, &header), "a header longer than the data");
        long_header[0] = 16;
        assert!(!header_matches(&long_header, &header), "a header too short");
    }
}
