//! The frame's entry points: prepare, its statistics and lights, and the recording calls,
//! each inside the panic boundary (`with_pass`).

use super::*;

/// The CPU work of one frame into ring slot `slot` (the host waited for the frame that last
/// used it). `*out` is the frame; its warnings go to the warning callback.
#[no_mangle]
pub unsafe extern "C" fn umbrage_pass_prepare(
    pass: UmbragePass,
    slot: u32,
    view: *const UmbrageView,
    lights: *const UmbrageLight,
    light_count: u32,
    out: *mut UmbrageFrame,
) -> UmbrageResult {
    with_pass(pass, |s| {
        // SAFETY: non-NULL checked; readable by the header's contract.
        let v = convert::view(unsafe { &*non_null(view, "view")? })?;
        let out = non_null(out, "out")? as *mut UmbrageFrame;
        let ls: Vec<engine::geom::Light> = if light_count == 0 {
            Vec::new()
        } else {
            // SAFETY: non-NULL checked; `light_count` readable lights by the header's contract.
            let raw = unsafe { std::slice::from_raw_parts(non_null(lights, "lights")?, light_count as usize) };
            raw.iter().enumerate().map(|(i, l)| convert::light(i, l)).collect::<Result<_, _>>()?
        };
        // SAFETY: read before anything changes: `culled` is a plain field of a readable struct.
        let culled = unsafe { (*view).culled } != 0;
        let frame = match culled {
            false => s.pass.prepare(slot as usize, &v, &ls)?,
            true => s.pass.prepare_culled(slot as usize, &v, &ls)?,
        };
        s.warn(&frame.warnings);
        let f = UmbrageFrame { pass: s.id, serial: frame.serial(), slot, lights: light_count };
        s.frames[slot as usize] = Some(frame);
        // SAFETY: non-NULL, writable by the header's contract.
        unsafe { out.write(f) };
        Ok(())
    })
}

/// The frame last prepared on `slot` was recorded but will never be submitted.
#[no_mangle]
pub extern "C" fn umbrage_pass_abandon_frame(pass: UmbragePass, slot: u32) -> UmbrageResult {
    with_pass(pass, |s| Ok(s.pass.abandon_frame(slot as usize)?))
}

/// The compute technique's GPU triangle counts into the frame's stats (after its fence).
#[no_mangle]
pub extern "C" fn umbrage_pass_read_back_counts(pass: UmbragePass, frame: UmbrageFrame) -> UmbrageResult {
    with_pass(pass, |s| {
        s.frame(&frame)?;
        let slot = frame.slot as usize;
        let mut f = s.frames[slot].take().ok_or_else(|| CError::new(UMBRAGE_ERROR_INTERNAL, "the frame vanished"))?;
        let r = s.pass.read_back_counts(&mut f);
        s.frames[slot] = Some(f);
        Ok(r?)
    })
}

/// The frame's statistics.
#[no_mangle]
pub unsafe extern "C" fn umbrage_frame_get_stats(pass: UmbragePass, frame: UmbrageFrame, out: *mut UmbrageFrameStats) -> UmbrageResult {
    with_pass(pass, |s| {
        let out = non_null(out, "out")? as *mut UmbrageFrameStats;
        // SAFETY: non-NULL; the host set sType (read before writing the rest).
        let stype = unsafe { (*out).sType };
        convert::check_stype(stype, UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_FRAME_STATS, "UmbrageFrameStats")?;
        let f = s.frame(&frame)?;
        let t = &f.totals;
        let st = UmbrageFrameStats {
            sType: stype,
            pNext: std::ptr::null_mut(),
            sideTriangles: t.triangles.sides,
            darkCapTriangles: t.triangles.dark_cap,
            lightCapTriangles: t.triangles.light_cap,
            indexBytes: t.index_bytes,
            vertexBytes: t.vertex_bytes,
            bytesSent: t.bytes_sent,
            draws: t.draws,
            casesCulled: t.cases.culled,
            casesZPass: t.cases.zpass,
            casesZFail: t.cases.zfail,
            casesZFailLightCap: t.cases.zfail_light_cap,
            cpuSilhouettesMs: f.cpu_ms.silhouettes,
            cpuPlanMs: f.cpu_ms.plan,
            cpuRecordMs: f.cpu_ms.record,
            warningCount: f.warnings.len() as u32,
            pendingUploads: f.pending_uploads() as u32,
        };
        // SAFETY: non-NULL, writable by the header's contract; its pNext stays the host's.
        let next = unsafe { (*out).pNext };
        // The chain first, so that an unknown struct leaves everything unwritten.
        let mut chain = Vec::new();
        let mut p = next;
        while !p.is_null() {
            // SAFETY: the header's contract: every chained struct starts with sType and pNext.
            let (stype, after) = unsafe { ((*p.cast::<UmbrageKeepStats>()).sType, (*p.cast::<UmbrageKeepStats>()).pNext) };
            if stype != UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_KEEP_STATS as u32 {
                return Err(CError::new(
                    UMBRAGE_ERROR_STRUCTURE_TYPE,
                    format!("UmbrageFrameStats::pNext: a struct with sType {stype} is not one this version fills"),
                ));
            }
            chain.push(p.cast::<UmbrageKeepStats>());
            if chain.len() > 16 {
                // (a cycle, or a chain no host needs: refused rather than walked forever)
                return Err(CError::new(UMBRAGE_ERROR_STRUCTURE_TYPE, "UmbrageFrameStats::pNext: more than 16 chained structs"));
            }
            p = after;
        }
        let keep = UmbrageKeepStats {
            sType: UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_KEEP_STATS as u32,
            pNext: std::ptr::null_mut(),
            pairsTotal: t.pairs_total,
            pairsKept: t.pairs_kept,
            pairsReplanned: t.pairs_replanned,
            keptBytes: t.kept_bytes,
            keptEvictions: t.kept_evictions,
        };
        // SAFETY: as above; each chained struct is writable and keeps its own pNext.
        unsafe {
            out.write(UmbrageFrameStats { pNext: next, ..st });
            for k in chain {
                let after = (*k).pNext;
                k.write(UmbrageKeepStats { pNext: after, ..keep });
            }
        }
        Ok(())
    })
}

/// What the host's lighting pass needs for light `light` of the frame: its scissor and depth
/// bounds (set them with `umbrage_cmd_light_state`, or read them here).
#[no_mangle]
pub unsafe extern "C" fn umbrage_frame_get_light(
    pass: UmbragePass,
    frame: UmbrageFrame,
    light: u32,
    out: *mut UmbrageLightInfo,
) -> UmbrageResult {
    with_pass(pass, |s| {
        let out = non_null(out, "out")? as *mut UmbrageLightInfo;
        // SAFETY: non-NULL; the host set sType.
        let stype = unsafe { (*out).sType };
        convert::check_stype(stype, UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_LIGHT_INFO, "UmbrageLightInfo")?;
        let f = s.frame(&frame)?;
        let l = f.lights.get(light as usize).ok_or_else(|| {
            CError::from(engine::Error::from(engine::error::Misuse::LightIndex { index: light as usize, lights: f.lights.len() }))
        })?;
        let (lo, hi) = l.depth_bounds_or_full();
        // SAFETY: non-NULL, writable by the header's contract; its pNext stays the host's.
        unsafe {
            let next = (*out).pNext;
            out.write(UmbrageLightInfo {
                sType: stype,
                pNext: next,
                scissor: l.scissor,
                hasDepthBounds: l.depth_bounds.is_some() as u32,
                minDepthBounds: lo,
                maxDepthBounds: hi,
                casterCount: l.stats.casters.len() as u32,
                triangles: l.stats.casters.iter().map(|c| c.triangles.total()).sum(),
            });
        }
        Ok(())
    })
}

/// Records the frame's caster uploads (outside any rendering; idempotent per frame).
#[no_mangle]
pub unsafe extern "C" fn umbrage_cmd_upload(pass: UmbragePass, command_buffer: VkCommandBuffer, frame: UmbrageFrame) -> UmbrageResult {
    with_pass(pass, |s| {
        let f = s.frame(&frame)?;
        // SAFETY: the header's contract (the Rust `cmd_upload`'s).
        Ok(unsafe { s.pass.cmd_upload(command_buffer, f) }?)
    })
}

/// Records what the frame needs before the host's rendering begins (uploads, the compute
/// technique's silhouettes, the ray-query structures). Required first in the render-pass model.
#[no_mangle]
pub unsafe extern "C" fn umbrage_cmd_before_rendering(
    pass: UmbragePass,
    command_buffer: VkCommandBuffer,
    frame: UmbrageFrame,
) -> UmbrageResult {
    with_pass(pass, |s| {
        let f = s.frame(&frame)?;
        // SAFETY: the header's contract (the Rust `cmd_before_rendering`'s).
        Ok(unsafe { s.pass.cmd_before_rendering(command_buffer, f) }?)
    })
}

/// Leaves light `light`'s shadow count in the stencil of `target` (non-zero: shadowed).
/// Dynamic rendering: outside any rendering (the pass begins its own and records the
/// declared layout transitions). Render-pass model: inside the host's subpass.
#[no_mangle]
pub unsafe extern "C" fn umbrage_cmd_determine(
    pass: UmbragePass,
    command_buffer: VkCommandBuffer,
    frame: UmbrageFrame,
    light: u32,
    target: *const UmbrageDepthStencilTarget,
) -> UmbrageResult {
    with_pass(pass, |s| {
        // SAFETY: non-NULL checked; readable by the header's contract.
        let t = convert::target(unsafe { &*non_null(target, "target")? })?;
        let f = s.frame(&frame)?;
        // SAFETY: the header's contract (the Rust `cmd_determine`'s).
        Ok(unsafe { s.pass.cmd_determine(command_buffer, f, light as usize, &t) }?)
    })
}

/// Sets light `light`'s viewport (over `extent`), scissor and depth bounds (where the pass
/// uses them): for the host's lighting pipeline, whose VIEWPORT, SCISSOR (and DEPTH_BOUNDS
/// when `UmbrageCapabilities::depthBounds`) states are dynamic.
#[no_mangle]
pub unsafe extern "C" fn umbrage_cmd_light_state(
    pass: UmbragePass,
    command_buffer: VkCommandBuffer,
    frame: UmbrageFrame,
    light: u32,
    extent: VkExtent2D,
) -> UmbrageResult {
    with_pass(pass, |s| {
        let f = s.frame(&frame)?;
        // SAFETY: the header's contract (the Rust `cmd_light_state`'s).
        Ok(unsafe { s.pass.cmd_light_state(command_buffer, f, light as usize, extent) }?)
    })
}

/// Records the transparent casters' light-intensity map of `light` into `map` (the pass's
/// `transmitFormat`, dynamic rendering only); `log_space` non-zero: additive log map.
#[no_mangle]
pub unsafe extern "C" fn umbrage_cmd_light_intensity(
    pass: UmbragePass,
    command_buffer: VkCommandBuffer,
    frame: UmbrageFrame,
    light: u32,
    target: *const UmbrageDepthStencilTarget,
    map: VkImageView,
    log_space: UmbrageBool,
) -> UmbrageResult {
    with_pass(pass, |s| {
        // SAFETY: non-NULL checked; readable by the header's contract.
        let t = convert::target(unsafe { &*non_null(target, "target")? })?;
        let f = s.frame(&frame)?;
        // SAFETY: the header's contract (the Rust `cmd_light_intensity`'s).
        Ok(unsafe { s.pass.cmd_light_intensity(command_buffer, f, light as usize, &t, map, log_space != 0) }?)
    })
}
