//! GPU timestamps, for benchmarks that split time between passes.

use std::sync::Arc;

use ash::vk;

use super::context::{Context, Device};
use super::error::{GpuError, Result, VkContext};

/// A pool of `capacity` timestamps written with `Recorder::timestamp`.
pub struct Timestamps {
    dev: Arc<Device>,
    pub(crate) pool: vk::QueryPool,
    capacity: u32,
}

impl Timestamps {
    pub fn new(ctx: &Context, capacity: u32) -> Result<Timestamps> {
        if !ctx.dev.info.timestamps {
            return Err(GpuError::Unsupported(format!(
                "device '{}' has no graphics timestamps",
                ctx.dev.info.name
            )));
        }
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(capacity.max(1));
        // SAFETY: valid device.
        let pool = unsafe { ctx.dev.raw.create_query_pool(&info, None) }.vk("vkCreateQueryPool")?;
        Ok(Timestamps { dev: ctx.dev.clone(), pool, capacity: capacity.max(1) })
    }

    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// Milliseconds from timestamp 0 to each of the first `count` timestamps (after the
    /// submission that wrote them has completed).
    pub fn read_ms(&self, count: u32) -> Result<Vec<f64>> {
        let count = count.min(self.capacity);
        let mut raw = vec![0u64; count as usize];
        // SAFETY: the submission has completed; WAIT makes unavailable results an error.
        unsafe {
            self.dev.raw.get_query_pool_results(
                self.pool,
                0,
                &mut raw,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .vk("vkGetQueryPoolResults")?;
        let period = self.dev.info.timestamp_period_ns as f64;
        let t0 = raw.first().copied().unwrap_or(0);
        Ok(raw.iter().map(|&t| t.wrapping_sub(t0) as f64 * period * 1e-6).collect())
    }
}

impl Drop for Timestamps {
    fn drop(&mut self) {
        // SAFETY: submissions wait for completion.
        unsafe { self.dev.raw.destroy_query_pool(self.pool, None) };
    }
}
