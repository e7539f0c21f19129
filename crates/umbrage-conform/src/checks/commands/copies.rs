//! `commands.blit_copy_color` and `commands.buffers`: the colour copies and blits the viewer
//! presents with, and the buffer updates and copies, byte for byte.

use super::*;

/// `commands.blit_copy_color`: a 7 x 5 RGBA8 image of distinct texels copied to its like and
/// blitted (NEAREST) to 16 x 9 in RGBA8 and BGRA8 — ratios with no texel-centre ties, so the
/// spec fixes every destination texel.
pub fn blit_copy_color(ctx: &Context) -> Result<CheckResult> {
    let (sw, sh, dw, dh) = (7u32, 5u32, 16u32, 9u32);
    let rgba = vk::Format::R8G8B8A8_UNORM;
    let bgra = vk::Format::B8G8R8A8_UNORM;
    let feats = |f: vk::Format| {
        // SAFETY: a format query on the context's valid physical device.
        unsafe { ctx.instance.get_physical_device_format_properties(ctx.physical, f) }.optimal_tiling_features
    };
    use vk::FormatFeatureFlags as F;
    let base = F::COLOR_ATTACHMENT | F::SAMPLED_IMAGE | F::TRANSFER_SRC | F::TRANSFER_DST;
    if !feats(rgba).contains(base | F::BLIT_SRC | F::BLIT_DST) {
        return Ok(CheckResult::skipped("blit_copy_color", "skipped: R8G8B8A8_UNORM cannot be blitted (BLIT_SRC/BLIT_DST)"));
    }
    let with_bgra = feats(bgra).contains(base | F::BLIT_DST);
    let texel = |x: u32, y: u32| [(x * 31 + 7) as u8, (y * 47 + 3) as u8, (x * 5 + y * 11) as u8, (200 + x + y) as u8];
    let src_bytes: Vec<u8> = (0..sh).flat_map(|y| (0..sw).flat_map(move |x| texel(x, y))).collect();
    let mut s = Scratch::new(ctx);
    let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT
        | vk::ImageUsageFlags::SAMPLED
        | vk::ImageUsageFlags::TRANSFER_SRC
        | vk::ImageUsageFlags::TRANSFER_DST;
    let color = vk::ImageAspectFlags::COLOR;
    let src = s.image(rgba, vk::Extent2D { width: sw, height: sh }, usage, color)?;
    let copy = s.image(rgba, vk::Extent2D { width: sw, height: sh }, usage, color)?;
    let mut blits = vec![(rgba, s.image(rgba, vk::Extent2D { width: dw, height: dh }, usage, color)?)];
    if with_bgra {
        blits.push((bgra, s.image(bgra, vk::Extent2D { width: dw, height: dh }, usage, color)?));
    }
    let upload = s.readback(src_bytes.len() as u64)?;
    s.buffers[upload].write(0, &src_bytes)?;
    let copy_bytes = (sw * sh * 4) as usize;
    let blit_bytes = (dw * dh * 4) as usize;
    let out = s.readback((copy_bytes + blits.len() * blit_bytes) as u64)?;
    let layers = vk::ImageSubresourceLayers { aspect_mask: color, mip_level: 0, base_array_layer: 0, layer_count: 1 };
    let (src_img, copy_img) = (&s.images[src], &s.images[copy]);
    let (up, down) = (s.buffers[upload].raw, s.buffers[out].raw);
    let blit_imgs: Vec<&Image> = blits.iter().map(|&(_, k)| &s.images[k]).collect();
    ctx.one_shot(|cb| {
        use vk::ImageLayout as L;
        let d = &ctx.device;
        let corner = |w: u32, h: u32| [vk::Offset3D::default(), vk::Offset3D { x: w as i32, y: h as i32, z: 1 }];
        transition(ctx, cb, src_img, L::UNDEFINED, L::TRANSFER_DST_OPTIMAL);
        transition(ctx, cb, copy_img, L::UNDEFINED, L::TRANSFER_DST_OPTIMAL);
        for img in &blit_imgs {
            transition(ctx, cb, img, L::UNDEFINED, L::TRANSFER_DST_OPTIMAL);
        }
        let whole = |w: u32, h: u32, offset: u64| vk::BufferImageCopy {
            buffer_offset: offset,
            buffer_row_length: 0,
            buffer_image_height: 0,
            image_subresource: layers,
            image_offset: vk::Offset3D::default(),
            image_extent: vk::Extent3D { width: w, height: h, depth: 1 },
        };
        // SAFETY: recording outside rendering; every image is in the layout named, the
        // buffers hold what is copied, all handles outlive the submission.
        unsafe {
            d.cmd_copy_buffer_to_image(cb, up, src_img.raw, L::TRANSFER_DST_OPTIMAL, &[whole(sw, sh, 0)]);
            transition(ctx, cb, src_img, L::TRANSFER_DST_OPTIMAL, L::TRANSFER_SRC_OPTIMAL);
            let region = vk::ImageCopy::default().src_subresource(layers).dst_subresource(layers).extent(vk::Extent3D {
                width: sw,
                height: sh,
                depth: 1,
            });
            d.cmd_copy_image(cb, src_img.raw, L::TRANSFER_SRC_OPTIMAL, copy_img.raw, L::TRANSFER_DST_OPTIMAL, &[region]);
            for img in &blit_imgs {
                let blit = vk::ImageBlit::default()
                    .src_subresource(layers)
                    .src_offsets(corner(sw, sh))
                    .dst_subresource(layers)
                    .dst_offsets(corner(dw, dh));
                d.cmd_blit_image(cb, src_img.raw, L::TRANSFER_SRC_OPTIMAL, img.raw, L::TRANSFER_DST_OPTIMAL, &[blit], vk::Filter::NEAREST);
            }
            // The copy then goes through the colour layouts the renderer and the viewer use.
            transition(ctx, cb, copy_img, L::TRANSFER_DST_OPTIMAL, L::COLOR_ATTACHMENT_OPTIMAL);
            transition(ctx, cb, copy_img, L::COLOR_ATTACHMENT_OPTIMAL, L::SHADER_READ_ONLY_OPTIMAL);
            transition(ctx, cb, copy_img, L::SHADER_READ_ONLY_OPTIMAL, L::TRANSFER_SRC_OPTIMAL);
            d.cmd_copy_image_to_buffer(cb, copy_img.raw, L::TRANSFER_SRC_OPTIMAL, down, &[whole(sw, sh, 0)]);
            for (k, img) in blit_imgs.iter().enumerate() {
                transition(ctx, cb, img, L::TRANSFER_DST_OPTIMAL, L::TRANSFER_SRC_OPTIMAL);
                let offset = (copy_bytes + k * blit_bytes) as u64;
                d.cmd_copy_image_to_buffer(cb, img.raw, L::TRANSFER_SRC_OPTIMAL, down, &[whole(dw, dh, offset)]);
            }
        }
        transfer_to_host_barrier(ctx, cb);
    })?;
    let got = s.buffers[out].read()?;
    let mut numbers = serde_json::Map::new();
    let mut fails = Vec::new();
    let copy_bad = (0..copy_bytes).filter(|&k| got[k] != src_bytes[k]).count();
    numbers.insert("copy_image_byte_mismatches".into(), json!(copy_bad));
    if copy_bad > 0 {
        crate::value_images::words("copy_image", &src_bytes[..copy_bytes], &got[..copy_bytes]);
        fails.push(format!("vkCmdCopyImage: {copy_bad} bytes differ"));
    }
    for (k, &(format, _)) in blits.iter().enumerate() {
        let base = copy_bytes + k * blit_bytes;
        let mut bad = 0;
        let mut want_bytes = got[base..base + blit_bytes].to_vec();
        for y in 0..dh {
            for x in 0..dw {
                // NEAREST: the source texel containing the destination centre mapped back,
                // u = (x + 0.5) * sw / dw (never an integer for these sizes).
                let (u, v) = ((2 * x + 1) * sw / (2 * dw), (2 * y + 1) * sh / (2 * dh));
                let [r, g, b, a] = texel(u, v);
                let want = if format == bgra { [b, g, r, a] } else { [r, g, b, a] };
                let at = base + ((y * dw + x) * 4) as usize;
                bad += usize::from(got[at..at + 4] != want);
                want_bytes[at - base..at - base + 4].copy_from_slice(&want);
            }
        }
        numbers.insert(format!("blit_{format:?}_texel_mismatches"), json!(bad));
        if bad > 0 {
            crate::value_images::words(&format!("blit_{format:?}"), &want_bytes, &got[base..base + blit_bytes]);
            fails.push(format!("vkCmdBlitImage to {format:?}: {bad} of {} texels differ", dw * dh));
        }
    }
    numbers.insert("bgra_blit".into(), json!(with_bgra));
    let what = "vkCmdCopyImage exact (kept through COLOR_ATTACHMENT and SHADER_READ_ONLY); vkCmdBlitImage NEAREST 7x5 -> 16x9 (RGBA8, and to BGRA8 where it can be a blit destination) exact";
    Ok(CheckResult::from_fails("blit_copy_color", fails, numbers, what))
}

/// `commands.buffers`: `vkCmdUpdateBuffer` at an offset, then `vkCmdCopyBuffer` of two regions
/// at offsets within the buffer: every byte as the spec puts it.
pub fn buffers(ctx: &Context) -> Result<CheckResult> {
    let size = 512usize;
    let mut s = Scratch::new(ctx);
    let b = s.readback(size as u64)?;
    let buf = s.buffers[b].raw;
    let data: Vec<u8> = (0..64u32).map(|k| (k * 37 + 5) as u8).collect();
    let (at, regions) = (16usize, [(16usize, 128usize, 40usize), (48, 300, 8)]);
    ctx.one_shot(|cb| {
        // SAFETY: recording outside rendering; offsets and sizes are multiples of 4 within the buffer.
        unsafe { ctx.device.cmd_update_buffer(cb, buf, at as u64, &data) };
        memory_barrier(
            ctx,
            cb,
            (vk::PipelineStageFlags2::ALL_TRANSFER, vk::AccessFlags2::TRANSFER_WRITE),
            (vk::PipelineStageFlags2::ALL_TRANSFER, vk::AccessFlags2::TRANSFER_READ | vk::AccessFlags2::TRANSFER_WRITE),
        );
        let copies: Vec<vk::BufferCopy> = regions
            .iter()
            .map(|&(src, dst, n)| vk::BufferCopy { src_offset: src as u64, dst_offset: dst as u64, size: n as u64 })
            .collect();
        // SAFETY: as above; the regions do not overlap each other or their sources.
        unsafe { ctx.device.cmd_copy_buffer(cb, buf, buf, &copies) };
        transfer_to_host_barrier(ctx, cb);
    })?;
    let mut want = vec![UNTOUCHED; size];
    want[at..at + data.len()].copy_from_slice(&data);
    for (src, dst, n) in regions {
        let chunk = want[src..src + n].to_vec();
        want[dst..dst + n].copy_from_slice(&chunk);
    }
    if crate::value_images::skewed() {
        want[0] ^= 0xff;
    }
    let got = s.buffers[b].read()?;
    let bad = (0..size).filter(|&k| got[k] != want[k]).count();
    let mut numbers = serde_json::Map::new();
    numbers.insert("byte_mismatches".into(), json!(bad));
    let fails = if bad > 0 { vec![format!("{bad} of {size} bytes differ")] } else { vec![] };
    if bad > 0 {
        crate::value_images::words("bytes", &want, got);
    }
    Ok(CheckResult::from_fails("buffers", fails, numbers, "vkCmdUpdateBuffer at an offset and vkCmdCopyBuffer of two regions: every byte"))
}
