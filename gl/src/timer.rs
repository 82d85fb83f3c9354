//! GPU time of one draw through a GL_TIME_ELAPSED query, and the decision of
//! whether that time can be trusted on this driver.

use anyhow::anyhow;
use glow::HasContext;
use twinray_common::explain;

pub struct Timer<'gl> {
    gl: &'gl glow::Context,
    query: glow::Query,
    /// False where the driver's numbers do not mean GPU time.
    reliable: bool,
}

impl<'gl> Timer<'gl> {
    pub fn new(gl: &'gl glow::Context, renderer: &str) -> anyhow::Result<Timer<'gl>> {
        // SAFETY: a fresh query object on the current context.
        let query = unsafe { gl.create_query() }.map_err(|e| anyhow!(e).context("glGenQueries"))?;
        // llvmpipe's TIME_ELAPSED does not bracket the work its rasteriser
        // threads do (Mesa 22.3: 1097 s for a first 97 ms frame, then 2-8 ms
        // for 55-60 ms frames), so wall time stands in there (docs/architecture.md). The
        // query still runs, so that the loop is the same on every driver;
        // only its result is dropped.
        let reliable = !renderer.contains("llvmpipe");
        explain::numbered(10, "glGenQueries (GL_TIME_ELAPSED)", || {
            let note = if reliable {
                ""
            } else {
                "; llvmpipe: the result is dropped (not GPU time), wall time is reported"
            };
            format!("one query object{note}")
        });
        Ok(Timer {
            gl,
            query,
            reliable,
        })
    }

    pub fn begin(&self) {
        // SAFETY: one query, never nested, on the current context.
        unsafe { self.gl.begin_query(glow::TIME_ELAPSED, self.query) }
    }

    pub fn end(&self) {
        // SAFETY: matches `begin`.
        unsafe { self.gl.end_query(glow::TIME_ELAPSED) }
    }

    /// Milliseconds of the last begin/end pair; waits for the result, which
    /// after glFinish is already there.
    pub fn result_ms(&self) -> Option<f64> {
        // SAFETY: the query has ended; GL_QUERY_RESULT is 64-bit nanoseconds.
        let ns = unsafe {
            self.gl
                .get_query_parameter_u64(self.query, glow::QUERY_RESULT)
        };
        self.reliable.then(|| ns as f64 / 1e6)
    }
}

impl Timer<'_> {
    /// Like `result_ms`, but `None` instead of waiting when the GPU has not
    /// finished the timed draw yet (the windowed loop never stalls on a query).
    pub fn try_result_ms(&self) -> Option<f64> {
        // SAFETY: the query has ended at least once.
        let ready = unsafe {
            self.gl
                .get_query_parameter_u32(self.query, glow::QUERY_RESULT_AVAILABLE)
        } != 0;
        if ready {
            self.result_ms()
        } else {
            None
        }
    }
}

impl Drop for Timer<'_> {
    fn drop(&mut self) {
        // SAFETY: query of this context, not active any more.
        unsafe { self.gl.delete_query(self.query) }
    }
}
