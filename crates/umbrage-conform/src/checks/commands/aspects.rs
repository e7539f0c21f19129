//! The aspect checks: clears and load ops per aspect (`clears`), aspect copies with offsets and
//! strides (`copy_aspects`), and layout transitions (`layouts`), each on every depth-stencil
//! format and image model.

use super::*;

fn models(ctx: &Context) -> Vec<Model> {
    let mut v = vec![Model::RenderPass];
    if ctx.features.dynamic_rendering {
        v.insert(0, Model::DynamicRendering);
    }
    v
}

/// `commands.clears`: load ops per aspect within a partial render area and
/// `vkCmdClearAttachments` per aspect mask, in a rendering instance and in a subpass, in every
/// depth-stencil format.
pub fn clears(ctx: &Context) -> Result<CheckResult> {
    let mut numbers = serde_json::Map::new();
    let mut fails = Vec::new();
    for format in ds_formats(ctx) {
        for model in models(ctx) {
            let label = format!("{}.{}", short(format), model.name());
            let mut s = Scratch::new(ctx);
            let (i, grid) = patterned(&mut s, format, model, vk::ImageUsageFlags::empty())?;
            let (depth, stencil) = read_aspects(&mut s, i, format, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)?;
            let (dm, sm) = compare_grid(format, &grid, &depth, &stencil);
            numbers.insert(label.clone(), json!({ "depth_mismatches": dm, "stencil_mismatches": sm }));
            if dm + sm > 0 {
                fails.push(format!("{label}: {dm} depth and {sm} stencil texels differ from the load ops' and clears' result"));
                let db = depth_texel_bytes(format);
                let bad = |t: usize| !depth_matches(format, &depth[t * db..(t + 1) * db], grid.depth[t]);
                aspect_images(&label, format, (&|t| grid.depth[t] as f64, &grid.stencil), (&depth, &stencil), &bad);
            }
        }
    }
    let what =
        "load ops per aspect within the render area and vkCmdClearAttachments per aspect mask (low 8 stencil bits, scissor ignored), \
                rendering instance and subpass, every format";
    Ok(CheckResult::from_fails("clears", fails, numbers, what))
}

/// `commands.copy_aspects`: each aspect copied at a buffer offset with a row length and image
/// height beyond the region, from an image offset.
pub fn copy_aspects(ctx: &Context) -> Result<CheckResult> {
    let mut numbers = serde_json::Map::new();
    let mut fails = Vec::new();
    let (ox, oy, cw, ch) = (3u32, 2u32, 40u32, 20u32);
    let (row, image_height) = (47u32, 23u32);
    for format in ds_formats(ctx) {
        let mut s = Scratch::new(ctx);
        let model = models(ctx)[0];
        let (i, _) = patterned(&mut s, format, model, vk::ImageUsageFlags::empty())?;
        // The reference: the same aspects copied whole and tightly packed (what
        // `commands.clears` holds to the model), so this check judges the region's addressing.
        let (ref_depth, ref_stencil) = read_aspects(&mut s, i, format, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)?;
        let db = depth_texel_bytes(format);
        // D24's top byte is undefined in both copies.
        let depth_bytes = if format == vk::Format::D24_UNORM_S8_UINT { 3 } else { db };
        let span = (image_height as usize * row as usize) * db;
        let (depth_at, stencil_at) = (256usize, 256 + span + 4 * 5);
        let size = stencil_at + image_height as usize * row as usize + 64;
        let b = s.readback(size as u64)?;
        let (img, buf) = (&s.images[i], s.buffers[b].raw);
        let region = |aspect, offset: usize| vk::BufferImageCopy {
            buffer_offset: offset as u64,
            buffer_row_length: row,
            buffer_image_height: image_height,
            image_subresource: vk::ImageSubresourceLayers { aspect_mask: aspect, mip_level: 0, base_array_layer: 0, layer_count: 1 },
            image_offset: vk::Offset3D { x: ox as i32, y: oy as i32, z: 0 },
            image_extent: vk::Extent3D { width: cw, height: ch, depth: 1 },
        };
        ctx.one_shot(|cb| {
            let att = vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
            transition(ctx, cb, img, att, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
            let regions = [region(vk::ImageAspectFlags::DEPTH, depth_at), region(vk::ImageAspectFlags::STENCIL, stencil_at)];
            // SAFETY: recording outside rendering; the image is in TRANSFER_SRC_OPTIMAL; the
            // buffer holds both regions (offsets multiples of 4, as depth-stencil copies need).
            unsafe { ctx.device.cmd_copy_image_to_buffer(cb, img.raw, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, buf, &regions) };
            transfer_to_host_barrier(ctx, cb);
        })?;
        let got = s.buffers[b].read()?;
        // Every byte: a region texel where the spec puts it, untouched everywhere else (but
        // D24's undefined top byte).
        let mut expected: Vec<Option<u8>> = vec![Some(UNTOUCHED); size];
        let (mut dm, mut sm) = (0usize, 0usize);
        for y in 0..ch as usize {
            for x in 0..cw as usize {
                let src = (oy as usize + y) * W as usize + ox as usize + x;
                let at = depth_at + (y * row as usize + x) * db;
                if got[at..at + depth_bytes] != ref_depth[src * db..src * db + depth_bytes] {
                    dm += 1;
                }
                for e in &mut expected[at..at + db] {
                    *e = None;
                }
                let at = stencil_at + y * row as usize + x;
                expected[at] = Some(ref_stencil[src]);
            }
        }
        for (k, e) in expected.iter().enumerate() {
            if let Some(v) = e {
                if got[k] != *v {
                    sm += 1;
                }
            }
        }
        numbers.insert(short(format).into(), json!({ "depth_mismatches": dm, "other_byte_mismatches": sm, "bytes": size }));
        if dm + sm > 0 {
            // Every byte the check knows: the region's depth bytes, its stencil, untouched elsewhere.
            let mut want: Vec<u8> = expected.iter().zip(got.iter()).map(|(e, g)| e.unwrap_or(*g)).collect();
            for y in 0..ch as usize {
                for x in 0..cw as usize {
                    let src = (oy as usize + y) * W as usize + ox as usize + x;
                    let at = depth_at + (y * row as usize + x) * db;
                    want[at..at + depth_bytes].copy_from_slice(&ref_depth[src * db..src * db + depth_bytes]);
                }
            }
            crate::value_images::words(short(format), &want, got);
            fails.push(format!(
                "{}: {dm} depth texels wrong, {sm} stencil or untouched bytes wrong (row length {row}, image height {image_height}, offsets {depth_at}/{stencil_at})",
                short(format)
            ));
        }
    }
    let what = "depth (2 bytes D16, 4 bytes X8D24/D32) and stencil (1 byte) aspects copied with buffer offsets, row length and image \
                height beyond the region and an image offset; nothing else written";
    Ok(CheckResult::from_fails("copy_aspects", fails, numbers, what))
}

/// `commands.layouts`: the pattern read back after a chain through every layout umbrage and
/// its hosts put a depth-stencil image in.
pub fn layouts(ctx: &Context) -> Result<CheckResult> {
    use vk::ImageLayout as L;
    let mut numbers = serde_json::Map::new();
    let mut fails = Vec::new();
    for format in ds_formats(ctx) {
        // SAFETY: a format query on the context's valid physical device.
        let props = unsafe { ctx.instance.get_physical_device_format_properties(ctx.physical, format) };
        let sampled = props.optimal_tiling_features.contains(vk::FormatFeatureFlags::SAMPLED_IMAGE);
        let mut chain = vec![L::DEPTH_STENCIL_READ_ONLY_OPTIMAL];
        if sampled {
            chain.push(L::SHADER_READ_ONLY_OPTIMAL);
        }
        if ctx.features.api_version >= vk::API_VERSION_1_1 {
            chain.push(L::DEPTH_ATTACHMENT_STENCIL_READ_ONLY_OPTIMAL);
        }
        chain.extend([L::TRANSFER_SRC_OPTIMAL, L::TRANSFER_DST_OPTIMAL, L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL]);
        let usage = vk::ImageUsageFlags::TRANSFER_DST | if sampled { vk::ImageUsageFlags::SAMPLED } else { vk::ImageUsageFlags::empty() };
        let mut s = Scratch::new(ctx);
        let (i, _) = patterned(&mut s, format, models(ctx)[0], usage)?;
        // The reference: the contents read before the chain (`commands.clears` holds them to
        // the model), so this check judges the transitions alone.
        let before = read_aspects(&mut s, i, format, L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)?;
        let img = &s.images[i];
        ctx.one_shot(|cb| {
            let mut from = L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
            for &to in &chain {
                transition(ctx, cb, img, from, to);
                from = to;
            }
        })?;
        let (depth, stencil) = read_aspects(&mut s, i, format, L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)?;
        let db = depth_texel_bytes(format);
        let kept = if format == vk::Format::D24_UNORM_S8_UINT { 3 } else { db };
        let dm = (0..(W * H) as usize).filter(|&t| depth[t * db..t * db + kept] != before.0[t * db..t * db + kept]).count();
        let sm = (0..(W * H) as usize).filter(|&t| stencil[t] != before.1[t]).count();
        let names: Vec<String> = chain.iter().map(|l| format!("{l:?}")).collect();
        numbers.insert(short(format).into(), json!({ "chain": names, "depth_mismatches": dm, "stencil_mismatches": sm }));
        if dm + sm > 0 {
            fails.push(format!("{}: {dm} depth and {sm} stencil texels changed through {}", short(format), names.join(" -> ")));
            let bad = |t: usize| depth[t * db..t * db + kept] != before.0[t * db..t * db + kept];
            let exp = |t: usize| depth_value(format, &before.0, t);
            aspect_images(short(format), format, (&exp, &before.1), (&depth, &stencil), &bad);
        }
    }
    let what = "depth and stencil kept through DEPTH_STENCIL_READ_ONLY, SHADER_READ_ONLY (where sampled), \
                DEPTH_ATTACHMENT_STENCIL_READ_ONLY (Vulkan 1.1), TRANSFER_SRC, TRANSFER_DST and back";
    Ok(CheckResult::from_fails("layouts", fails, numbers, what))
}
