//! GPU timestamps around the draw.
//!
//! The CPU cannot see when the GPU starts and finishes work, only when a fence
//! says it is done, which includes submission and wake-up latency. So the
//! command buffer itself writes two timestamps into a *query pool*, and the app
//! reads them after the frame. They are raw ticks: `timestampPeriod` says how
//! many nanoseconds a tick is, and the queue family's `timestampValidBits` says
//! how many low bits count (0: this queue cannot write timestamps at all).

use crate::barrier::Timestamp;
use crate::device::Device;
use anyhow::{Context, Result};
use ash::vk;
use twinray_common::explain;

pub struct Timestamps {
    device: ash::Device,
    pool: vk::QueryPool,
    /// Nanoseconds per tick.
    period_ns: f64,
    /// The valid low bits; the counter wraps at their width.
    mask: u64,
}

impl Timestamps {
    /// `None` where the queue cannot time: the report then has no `gpu_ms`.
    pub fn new(device: &Device) -> Result<Option<Timestamps>> {
        let bits = device.timestamp_valid_bits;
        if bits == 0 {
            return Ok(None);
        }
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(2);
        // SAFETY: a create on the live device; the Timestamps returned owns the pool and destroys
        // it.
        let pool = unsafe { device.device.create_query_pool(&info, None) }
            .context("creating the timestamp query pool")?;
        explain::numbered(10, "VkQueryPool (2 TIMESTAMP queries)", || {
            format!(
                "timestampPeriod {} ns per tick, timestampValidBits {bits}; results read as 64-bit",
                device.properties.limits.timestamp_period
            )
        });
        Ok(Some(Timestamps {
            device: device.device.clone(),
            pool,
            period_ns: device.properties.limits.timestamp_period as f64,
            mask: if bits >= 64 {
                u64::MAX
            } else {
                (1u64 << bits) - 1
            },
        }))
    }

    /// Queries must be reset before each use; this happens on the GPU, every frame,
    /// inside the recorded commands (outside the render pass, where resets must be).
    pub fn record_reset(&self, cmd: vk::CommandBuffer) {
        // SAFETY: every caller passes the command buffer it is recording, outside
        // a render pass (Commands::record, compute.rs, frames.rs); the pool is
        // self's, alive while that buffer can run (its owner waits for the GPU).
        unsafe { self.device.cmd_reset_query_pool(cmd, self.pool, 0, 2) };
    }

    /// Query 0 when the GPU starts the commands after it (TOP_OF_PIPE), query 1
    /// when it has finished everything before it (BOTTOM_OF_PIPE).
    pub fn record(&self, cmd: vk::CommandBuffer, query: u32) {
        let stage = if query == 0 {
            Timestamp::Start.stage()
        } else {
            Timestamp::End.stage()
        };
        assert!(query < 2, "the pool holds two queries");
        // SAFETY: as for record_reset; the query exists (checked above) and was
        // reset earlier in the same command buffer.
        unsafe {
            self.device
                .cmd_write_timestamp(cmd, stage, self.pool, query)
        };
    }

    /// The frame's GPU time in milliseconds. WAIT makes this block until both
    /// results exist (they do: the fence has signalled); 64-bit results because
    /// 32-bit ticks wrap within seconds on fast clocks.
    pub fn read_ms(&self) -> Result<f64> {
        let mut ticks = [0u64; 2];
        let flags = vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT;
        // SAFETY: `ticks` holds the two 64-bit results TYPE_64 asks for; every
        // caller reads after the fence of a submission that wrote both queries,
        // so WAIT cannot wait for ever.
        unsafe {
            self.device
                .get_query_pool_results(self.pool, 0, &mut ticks, flags)
        }
        .context("reading the timestamps")?;
        let elapsed = ticks[1].wrapping_sub(ticks[0]) & self.mask;
        Ok(elapsed as f64 * self.period_ns / 1e6)
    }
}

impl Drop for Timestamps {
    fn drop(&mut self) {
        // SAFETY: no command buffer using the pool is pending (see Commands::drop).
        unsafe { self.device.destroy_query_pool(self.pool, None) };
    }
}

/// What a headless compute frame records, and what its two timestamps bracket.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Span {
    /// The barrier that orders the frame after the last one is inside the
    /// span (the plan's `timed_barrier`). By default the first timestamp
    /// follows it: the span is the dispatch alone, as OpenGL times its dispatch.
    pub barrier: bool,
    /// Dispatches of the tracer in the span: 1, or 2 with no barrier between
    /// them (the plan's `frame_dispatches`), both writing the same values.
    pub dispatches: u32,
}

impl Span {
    /// One dispatch, timed alone: every frame that is not a laboratory's.
    pub const DISPATCH: Span = Span {
        barrier: false,
        dispatches: 1,
    };

    /// The span the plan asks for (its `timed_barrier` and `frame_dispatches`).
    pub fn of(plan: &twinray_common::plan::RunPlan) -> Span {
        Span {
            barrier: plan.timed_barrier,
            dispatches: plan.frame_dispatches,
        }
    }
}
