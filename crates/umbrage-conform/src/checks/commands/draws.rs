//! The `commands.*` checks that draw: `queries`, `scissor` and `indirect` (the parent module
//! says what each holds).

use super::*;

/// Two triangles covering the integer rectangle `[x0, y0, x1, y1]` at depth `z`.
fn quad(r: [f32; 4], z: f32) -> Vec<[f32; 4]> {
    let mut q = Vec::new();
    rect(&mut q, r, true);
    q.into_iter().map(|p| [p[0], p[1], z, 1.0]).collect()
}

fn needs_dynamic_rendering(ctx: &Context, name: &str) -> Option<CheckResult> {
    (!ctx.features.dynamic_rendering).then(|| {
        let v = &ctx.info.api_version;
        CheckResult::skipped(name, &format!("skipped: draws through dynamic rendering (Vulkan 1.3); the device has Vulkan {v}"))
    })
}

/// `commands.queries`: occlusion, pipeline-statistics and timestamp queries recorded and read
/// as the renderer's counters do, and read back with other offsets, strides and flags.
pub fn queries(ctx: &Context) -> Result<CheckResult> {
    if let Some(r) = needs_dynamic_rendering(ctx, "queries") {
        return Ok(r);
    }
    let f = &ctx.features;
    let format = ctx.depth_format;
    let mvp = harness::pixel_ortho(W, H);
    let incr = PipeSpec::stencil(vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::INCREMENT_AND_WRAP);
    // 0: 10 x 6 pixels; 1: 7 x 3; 2: five triangles, two entirely left of the image.
    let mut five = quad([0.0, 0.0, 8.0, 8.0], 0.5);
    five.extend(&quad([-40.0, 0.0, -30.0, 8.0], 0.5));
    let again = five[0..3].to_vec();
    five.extend(again);
    let draws = [
        DrawCall { spec: incr, mvp, vertices: quad([2.0, 3.0, 12.0, 9.0], 0.5), indices: Indices::None },
        DrawCall { spec: incr, mvp, vertices: quad([30.0, 10.0, 37.0, 13.0], 0.5), indices: Indices::None },
        DrawCall { spec: incr, mvp, vertices: five, indices: Indices::None },
    ];
    let prepared = Draws::new(ctx, format, &draws)?;
    let result = (|| -> Result<CheckResult> {
        let mut s = Scratch::new(ctx);
        let i = s.image(format, vk::Extent2D { width: W, height: H }, vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT, DS)?;
        let occ = s.query_pool(vk::QueryType::OCCLUSION, 8, vk::QueryPipelineStatisticFlags::empty())?;
        use vk::QueryPipelineStatisticFlags as P;
        let stat_flags = P::INPUT_ASSEMBLY_PRIMITIVES | P::VERTEX_SHADER_INVOCATIONS | P::CLIPPING_PRIMITIVES;
        let stats = match f.pipeline_statistics_query {
            true => Some(s.query_pool(vk::QueryType::PIPELINE_STATISTICS, 2, stat_flags)?),
            false => None,
        };
        let stamps = match f.timestamps {
            true => Some(s.query_pool(vk::QueryType::TIMESTAMP, 2, P::empty())?),
            false => None,
        };
        let control = if f.occlusion_query_precise { vk::QueryControlFlags::PRECISE } else { vk::QueryControlFlags::empty() };
        let img = &s.images[i];
        ctx.one_shot(|cb| {
            let d = &ctx.device;
            let area = full();
            // SAFETY: recording; the pools, image and draws outlive the submission; every query
            // is reset before it is begun, begun and ended once, inside one rendering instance.
            unsafe {
                d.cmd_reset_query_pool(cb, occ, 0, 8);
                d.cmd_reset_query_pool(cb, occ, 2, 4);
                if let Some(p) = stats {
                    d.cmd_reset_query_pool(cb, p, 0, 2);
                }
                if let Some(p) = stamps {
                    d.cmd_reset_query_pool(cb, p, 0, 2);
                    write_timestamp(ctx, cb, p, 0);
                }
            }
            transition(ctx, cb, img, vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
            let att = cleared_depth_stencil(img.view, (1.0, 0));
            let info = vk::RenderingInfo::default().render_area(area).layer_count(1).depth_attachment(&att).stencil_attachment(&att);
            let viewport = vk::Viewport { x: 0.0, y: 0.0, width: W as f32, height: H as f32, min_depth: 0.0, max_depth: 1.0 };
            // SAFETY: as above.
            unsafe {
                d.cmd_begin_rendering(cb, &info);
                d.cmd_set_viewport(cb, 0, &[viewport]);
                d.cmd_begin_query(cb, occ, 2, control);
                prepared.record(ctx, cb, 0, area);
                d.cmd_end_query(cb, occ, 2);
                d.cmd_begin_query(cb, occ, 3, control);
                d.cmd_end_query(cb, occ, 3);
                d.cmd_begin_query(cb, occ, 5, control);
                prepared.record(ctx, cb, 1, area);
                d.cmd_end_query(cb, occ, 5);
                if let Some(p) = stats {
                    d.cmd_begin_query(cb, p, 1, vk::QueryControlFlags::empty());
                    prepared.record(ctx, cb, 2, area);
                    d.cmd_end_query(cb, p, 1);
                }
                d.cmd_end_rendering(cb);
                if let Some(p) = stamps {
                    write_timestamp(ctx, cb, p, 1);
                }
            }
        })?;
        let (fails, numbers) = read_queries(ctx, occ, stats, stamps)?;
        let what = "occlusion queries reset by sub-range, counted (precise where the device can), read from a first query in 64 and \
                    32 bits and with availability (unavailable: 0, VK_NOT_READY); pipeline statistics in flag-bit order; timestamps in order";
        Ok(CheckResult::from_fails("queries", fails, numbers, what))
    })();
    prepared.destroy(ctx);
    result
}

/// Reads `commands.queries`' results back and judges them: (failures, numbers). A failure
/// draws every count against its accepted range (`counts.bars.png`, in the order of the
/// numbers: occlusion 64-bit, 32-bit, with availability; statistics; timestamps).
fn read_queries(
    ctx: &Context,
    occ: vk::QueryPool,
    stats: Option<vk::QueryPool>,
    stamps: Option<vk::QueryPool>,
) -> Result<(Vec<String>, serde_json::Map<String, serde_json::Value>)> {
    use crate::value_images::Bar;
    let mut numbers = serde_json::Map::new();
    let mut fails = Vec::new();
    let d = &ctx.device;
    let exact = ctx.features.occlusion_query_precise;
    // The test seam: a count the device cannot have drawn.
    let (want60, want0) = if crate::value_images::skewed() { (61, 1) } else { (60, 0) };
    let mut bars = Vec::new();
    let count_bar = |got: u64, want: u64| Bar {
        lo: if exact { want as f64 } else { want.min(1) as f64 },
        hi: if exact { want as f64 } else { (got.max(want)) as f64 },
        got: got as f64,
    };
    let count_ok = |got: u64, want: u64| if exact { got == want } else { (got > 0) == (want > 0) };
    let mut q64 = [0u64; 2];
    // SAFETY: one_shot waited for the submission (here and below); each slice
    // holds `len` results of the flags' size and layout.
    unsafe { d.get_query_pool_results(occ, 2, &mut q64, vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT) }
        .map_err(vkerr("vkGetQueryPoolResults"))?;
    let mut q32 = [0u32; 2];
    // SAFETY: as above.
    unsafe { d.get_query_pool_results(occ, 2, &mut q32, vk::QueryResultFlags::WAIT) }.map_err(vkerr("vkGetQueryPoolResults"))?;
    // Queries 5 (ended) and 6 (reset, never begun) with availability, without waiting: the
    // call must say VK_NOT_READY, write 5's count and a non-zero availability ("non-zero if
    // the query's status was available": SwiftShader writes 2, lavapipe 1), and 6's 0.
    let mut avail = [[0u64, 7], [0, 7]];
    // SAFETY: as above; two u64 per query (count, availability).
    let r =
        unsafe { d.get_query_pool_results(occ, 5, &mut avail, vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WITH_AVAILABILITY) };
    numbers.insert("occlusion_64".into(), json!(q64));
    numbers.insert("occlusion_32".into(), json!(q32));
    numbers.insert("occlusion_with_availability".into(), json!(avail));
    numbers.insert("precise".into(), json!(exact));
    bars.extend([count_bar(q64[0], want60), count_bar(q64[1], want0)]);
    if !(count_ok(q64[0], want60) && q64[1] == want0) {
        fails.push(format!("occlusion queries 2..4 (64-bit): {q64:?}, want [{want60}, {want0}]"));
    }
    bars.extend([count_bar(q32[0] as u64, q64[0]), count_bar(q32[1] as u64, 0)]);
    if q32[0] as u64 != q64[0] || q32[1] != 0 {
        fails.push(format!("occlusion queries 2..4 (32-bit): {q32:?}, the 64-bit read gave {q64:?}"));
    }
    bars.extend([count_bar(avail[0][0], 21), Bar { lo: 1.0, hi: avail[0][1].max(1) as f64, got: avail[0][1] as f64 }]);
    bars.push(count_bar(avail[1][1], 0));
    if !count_ok(avail[0][0], 21) || avail[0][1] == 0 || avail[1][1] != 0 {
        fails.push(format!("queries 5..7 with availability: {avail:?}, want [[21, non-zero], [_, 0]]"));
    }
    match r {
        Err(vk::Result::NOT_READY) => {}
        other => fails.push(format!("reading an unavailable query without WAIT returned {other:?}, not VK_NOT_READY")),
    }
    if let Some(p) = stats {
        let mut raw = [[0u64; 3]; 1];
        // SAFETY: as above; three u64 per query, in flag-bit order.
        unsafe { d.get_query_pool_results(p, 1, &mut raw, vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT) }
            .map_err(vkerr("vkGetQueryPoolResults"))?;
        let [ia, vs, clip] = raw[0];
        numbers.insert(
            "statistics".into(),
            json!({ "input_assembly_primitives": ia, "vertex_shader_invocations": vs, "clipping_primitives": clip }),
        );
        // Five triangles (15 vertices, not indexed), two of them outside the view: exactly
        // 5 assembled; at least the visible three's 9 vertices shaded; 3 to 5 out of clipping.
        let range = |lo: u64, hi: u64, got: u64| Bar { lo: lo as f64, hi: hi as f64, got: got as f64 };
        bars.extend([range(5, 5, ia), range(9, 45, vs), range(3, 5, clip)]);
        if ia != 5 || !(9..=45).contains(&vs) || !(3..=5).contains(&clip) {
            fails.push(format!(
                "pipeline statistics [input assembly primitives, vertex invocations, clipping primitives] = {:?}, want [5, 9..=45, 3..=5]",
                raw[0]
            ));
        }
    }
    if let Some(p) = stamps {
        let mut t = [0u64; 2];
        // SAFETY: as above.
        unsafe { d.get_query_pool_results(p, 0, &mut t, vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT) }
            .map_err(vkerr("vkGetQueryPoolResults"))?;
        numbers.insert("timestamps".into(), json!(t));
        bars.push(Bar { lo: t[0] as f64, hi: t[1].max(t[0]) as f64, got: t[1] as f64 });
        if t[1] < t[0] {
            fails.push(format!("the later timestamp {} is before the earlier {}", t[1], t[0]));
        }
    }
    if !fails.is_empty() {
        crate::value_images::bars("counts", &bars);
    }
    Ok((fails, numbers))
}

/// Records a timestamp after every earlier command (synchronization2 where the device has it).
///
/// # Safety
/// `cb` is recording; `query` of `pool` (a timestamp pool) was reset and is written once.
unsafe fn write_timestamp(ctx: &Context, cb: vk::CommandBuffer, pool: vk::QueryPool, query: u32) {
    // SAFETY: the caller's contract.
    unsafe {
        if ctx.features.synchronization2 {
            ctx.device.cmd_write_timestamp2(cb, vk::PipelineStageFlags2::ALL_COMMANDS, pool, query);
        } else {
            ctx.device.cmd_write_timestamp(cb, vk::PipelineStageFlags::BOTTOM_OF_PIPE, pool, query);
        }
    }
}

/// `commands.scissor`: full-image quads through per-draw scissors — inside, straddling the
/// image's edge and past it, and empty: only the scissored pixels change.
pub fn scissor(ctx: &Context) -> Result<CheckResult> {
    if let Some(r) = needs_dynamic_rendering(ctx, "scissor") {
        return Ok(r);
    }
    let mvp = harness::pixel_ortho(W, H);
    let scissors = [rect2d(5, 3, 20, 10), rect2d(50, 20, 30, 30), rect2d(0, 0, 0, 9), rect2d(10, 0, 3, 32)];
    let mut g = Grid::new(1.0, 0);
    let draws: Vec<DrawCall> = scissors
        .iter()
        .enumerate()
        .map(|(k, &sc)| {
            let mut spec = PipeSpec::replace(k as u32 + 1);
            spec.scissor = Some(sc);
            g.fill(sc, None, Some(k as u8 + 1));
            DrawCall { spec, mvp, vertices: quad([0.0, 0.0, W as f32, H as f32], 0.5), indices: Indices::None }
        })
        .collect();
    let rb = harness::render(ctx, ctx.depth_format, W, H, 1.0, 0, &draws)?;
    let bad = (0..g.stencil.len()).filter(|&i| rb.stencil[i] != g.stencil[i]).count();
    if bad > 0 {
        crate::image_sink::stencil_mismatch(W, H, &g.stencil, &vec![true; g.stencil.len()], &rb.stencil);
    }
    let mut numbers = serde_json::Map::new();
    numbers.insert("mismatched_pixels".into(), json!(bad));
    let fails = if bad > 0 { vec![format!("{bad} pixels differ from the scissors' coverage")] } else { vec![] };
    Ok(CheckResult::from_fails(
        "scissor",
        fails,
        numbers,
        "per-draw scissors (inside, past the image's edge, empty) bound coverage exactly",
    ))
}

/// `commands.indirect`: indexed indirect draws, one record per call at non-zero offsets, with
/// `firstIndex`, `vertexOffset` and an empty record, against the same coverage computed directly.
pub fn indirect(ctx: &Context) -> Result<CheckResult> {
    if let Some(r) = needs_dynamic_rendering(ctx, "indirect") {
        return Ok(r);
    }
    let mvp = harness::pixel_ortho(W, H);
    let rects = [[2.0, 2.0, 20.0, 12.0], [10.0, 8.0, 40.0, 30.0], [44.0, 1.0, 60.0, 20.0]];
    // A decoy triangle at vertex 0: drawn only by a record read from the wrong place.
    let mut vertices = quad([0.0, 0.0, W as f32, H as f32], 0.5)[0..3].to_vec();
    for r in rects {
        vertices.extend(quad(r, 0.5));
    }
    let indices: Vec<u16> = (0..vertices.len() as u16).collect();
    let rec = |index_count, instance_count, first_index, vertex_offset| vk::DrawIndexedIndirectCommand {
        index_count,
        instance_count,
        first_index,
        vertex_offset,
        first_instance: 0,
    };
    // Rect 0 through first_index 3; rect 1 through first_index 0 and vertex_offset 9; an empty
    // record (instance count 0) over rect 2; rect 2 twice (two instances).
    let records = vec![rec(6, 1, 3, 0), rec(6, 1, 0, 9), rec(6, 0, 15, 0), rec(6, 2, 15, 0)];
    let spec = PipeSpec::stencil(vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::INCREMENT_AND_WRAP);
    let rb = harness::render(
        ctx,
        ctx.depth_format,
        W,
        H,
        1.0,
        0,
        &[DrawCall { spec, mvp, vertices, indices: Indices::Indirect16 { indices, records, lead_in: 3 } }],
    )?;
    let mut want = vec![0u8; (W * H) as usize];
    for (r, times) in rects.iter().zip([1u8, 1, 2]) {
        for y in r[1] as u32..r[3] as u32 {
            for x in r[0] as u32..r[2] as u32 {
                want[(y * W + x) as usize] += times;
            }
        }
    }
    if crate::value_images::skewed() {
        want[0] = want[0].wrapping_add(1);
    }
    let bad = (0..want.len()).filter(|&i| rb.stencil[i] != want[i]).count();
    if bad > 0 {
        crate::image_sink::stencil_mismatch(W, H, &want, &vec![true; want.len()], &rb.stencil);
    }
    let mut numbers = serde_json::Map::new();
    numbers.insert("mismatched_pixels".into(), json!(bad));
    let fails = if bad > 0 { vec![format!("{bad} pixels differ from the records' coverage")] } else { vec![] };
    let what = "vkCmdDrawIndexedIndirect per record at offsets 60..120 (firstIndex, vertexOffset, instanceCount 0 and 2) exact";
    Ok(CheckResult::from_fails("indirect", fails, numbers, what))
}
