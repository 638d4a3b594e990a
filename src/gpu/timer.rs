//! GPU timestamps around kernel dispatches.

use super::context::{Context, Shared};
use crate::Result;
use ash::vk;
use std::sync::Arc;

/// A pool of timestamp pairs; pair `i` brackets one dispatch.
pub struct GpuTimer {
    shared: Arc<Shared>,
    pool: vk::QueryPool,
    pairs: u32,
    period_ns: f64,
}

impl GpuTimer {
    /// None when the device's compute queue cannot write timestamps.
    pub fn new(ctx: &Context, pairs: u32) -> Result<Option<GpuTimer>> {
        let Some(period_ns) = ctx.info().timestamp_period_ns else {
            return Ok(None);
        };
        let info = vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(2 * pairs);
        let pool = unsafe { ctx.shared.device.create_query_pool(&info, None) }?;
        Ok(Some(GpuTimer { shared: ctx.shared.clone(), pool, pairs, period_ns }))
    }

    /// Resets every pair; record before the first `begin` in a command buffer.
    pub fn reset(&self, cmd: vk::CommandBuffer) {
        unsafe { self.shared.device.cmd_reset_query_pool(cmd, self.pool, 0, 2 * self.pairs) };
    }

    pub fn begin(&self, cmd: vk::CommandBuffer, pair: u32) {
        unsafe {
            self.shared.device.cmd_write_timestamp(cmd, vk::PipelineStageFlags::TOP_OF_PIPE, self.pool, 2 * pair)
        };
    }

    pub fn end(&self, cmd: vk::CommandBuffer, pair: u32) {
        unsafe {
            self.shared.device.cmd_write_timestamp(cmd, vk::PipelineStageFlags::BOTTOM_OF_PIPE, self.pool, 2 * pair + 1)
        };
    }

    /// Seconds between each pair's timestamps, once the command buffer has completed.
    pub fn read(&self, pairs: u32) -> Result<Vec<f64>> {
        let mut ticks = vec![0u64; 2 * pairs as usize];
        unsafe {
            self.shared.device.get_query_pool_results(
                self.pool,
                0,
                &mut ticks,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }?;
        Ok(ticks.chunks(2).map(|t| t[1].wrapping_sub(t[0]) as f64 * self.period_ns * 1e-9).collect())
    }
}

impl Drop for GpuTimer {
    fn drop(&mut self) {
        unsafe { self.shared.device.destroy_query_pool(self.pool, None) };
    }
}
