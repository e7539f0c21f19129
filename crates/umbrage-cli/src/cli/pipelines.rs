//! `umbrage info --pipelines`: creates every pipeline the renderer and `ShadowPass` can create
//! on the device, records nothing, and prints one line per pipeline with its creation time
//! (the driver's `vkCreate*Pipelines`). The exit status is non-zero when any creation fails.
//! Run it on every driver to see which pipelines its shader compiler struggles with
//! (docs/drivers/pipelines.md); `UMBRAGE_PIPELINE_TRACE=1` names each one before it is created,
//! so a creation that never returns is named too.

use ash::vk;
use umbrage::gpu::creation::{self, Creation};
use umbrage::gpu::Context;
use umbrage::pass::{self as sp, ShadowPass, ShadowPassDesc};
use umbrage::Result;
use umbrage_render::{RenderOptions, Renderer};

/// One configuration's creations, or why it could not be set up.
pub struct Group {
    /// What was created, e.g. `ShadowPass 4x reverse-Z render-pass`.
    pub name: String,
    /// Its pipelines, in creation order.
    pub creations: Vec<Creation>,
    /// The error that ended the configuration early, if any.
    pub error: Option<String>,
    /// Why a configuration was not attempted on this device.
    pub not_attempted: Option<String>,
}

/// The sample counts to cover: 1, and 4 where the device's frame supports it.
fn sample_counts(ctx: &Context) -> Vec<u32> {
    [1, 4].into_iter().filter(|&n| n == 1 || ctx.features.frame_sample_counts & n != 0).collect()
}

/// A render pass with one depth-stencil attachment (the host of the render-pass model).
fn render_pass(ctx: &Context, samples: u32) -> Result<(vk::RenderPass, sp::RenderPassTarget)> {
    let flags = vk::SampleCountFlags::from_raw(samples);
    let att = [vk::AttachmentDescription::default()
        .format(ctx.depth_format)
        .samples(flags)
        .load_op(vk::AttachmentLoadOp::LOAD)
        .store_op(vk::AttachmentStoreOp::STORE)
        .stencil_load_op(vk::AttachmentLoadOp::LOAD)
        .stencil_store_op(vk::AttachmentStoreOp::STORE)
        .initial_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
        .final_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)];
    let ds = vk::AttachmentReference { attachment: 0, layout: vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL };
    let sub = [vk::SubpassDescription::default().pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS).depth_stencil_attachment(&ds)];
    let info = vk::RenderPassCreateInfo::default().attachments(&att).subpasses(&sub);
    // SAFETY: creation on a valid device from locals; destroyed by the caller.
    let rp = unsafe { ctx.device.create_render_pass(&info, None) }.map_err(umbrage::Error::vk("vkCreateRenderPass"))?;
    let target =
        sp::RenderPassTarget { render_pass: rp, subpass: 0, depth_stencil_format: ctx.depth_format, samples: flags, color_attachments: 0 };
    Ok((rp, target))
}

/// Every `ShadowPass` configuration (samples, depth direction and mode, target model) with
/// every optional pipeline, then the compute silhouettes'.
fn pass_groups(ctx: &Context, out: &mut Vec<Group>) {
    let f = &ctx.features;
    let features = sp::EnabledFeatures {
        depth_clamp: f.depth_clamp,
        depth_bounds: f.depth_bounds,
        index_type_uint8: f.index_type_uint8,
        ray_query: f.ray_query,
        mesh_shader: f.mesh_shader,
        draw_indirect_first_instance: f.draw_indirect_first_instance,
        multi_draw_indirect: f.multi_draw_indirect,
        draw_indirect_count: f.draw_indirect_count,
        task_shader: f.task_shader,
    };
    let mut modes = vec![sp::DepthMode::Infinite];
    if f.depth_clamp {
        modes.push(sp::DepthMode::Clamp);
    }
    for samples in sample_counts(ctx) {
        for direction in [sp::DepthDirection::Forward, sp::DepthDirection::Reverse] {
            for &mode in &modes {
                for render_pass_model in [false, true] {
                    let name = format!(
                        "ShadowPass {samples}x {} {} {}",
                        direction.name(),
                        if mode == sp::DepthMode::Clamp { "clamp" } else { "infinite" },
                        if render_pass_model { "render-pass" } else { "dynamic-rendering" }
                    );
                    creation::take();
                    let mut rp = None;
                    let r = (|| -> Result<()> {
                        let target = match render_pass_model {
                            true => {
                                let (handle, target) = render_pass(ctx, samples)?;
                                rp = Some(handle);
                                sp::TargetModel::RenderPass(target)
                            }
                            false => sp::TargetModel::DynamicRendering,
                        };
                        let dynamic = !render_pass_model;
                        let desc = ShadowPassDesc {
                            depth_stencil_format: ctx.depth_format,
                            pipeline_cache: ctx.pipeline_cache,
                            samples,
                            depth_direction: direction,
                            depth_mode: mode,
                            target,
                            features,
                            transmit_format: dynamic.then_some(vk::Format::R16G16B16A16_SFLOAT),
                            debug_color_format: dynamic.then_some(vk::Format::R16G16B16A16_SFLOAT),
                            ..Default::default()
                        };
                        let mut pass = ShadowPass::new(&ctx.instance, ctx.physical, &ctx.device, (*ctx.allocator).clone(), &desc)?;
                        pass.create_pipelines(sp::Technique::Compute)
                    })();
                    if let Some(rp) = rp {
                        // SAFETY: the pass that used it was dropped; nothing was recorded.
                        unsafe { ctx.device.destroy_render_pass(rp, None) };
                    }
                    out.push(Group { name, creations: creation::take(), error: r.err().map(|e| e.to_string()), not_attempted: None });
                }
            }
        }
    }
}

/// Creates everything, returning the groups and the context back.
pub fn create_all(ctx: Context) -> (Vec<Group>, Option<Context>) {
    creation::record(true);
    let mut out = Vec::new();
    pass_groups(&ctx, &mut out);
    if ctx.null_hardware() {
        out.push(Group {
            name: "Renderer".into(),
            creations: Vec::new(),
            error: None,
            not_attempted: Some(
                "null hardware has no host-visible memory type, and the renderer allocates its staging and readback \
                 buffers before its own pipelines (the shadow pass's, above, are the same ones it would create)"
                    .into(),
            ),
        });
        creation::record(false);
        return (out, Some(ctx));
    }
    let mut ctx = Some(ctx);
    for samples in sample_counts(ctx.as_ref().expect("present")) {
        let Some(c) = ctx.take() else { break };
        creation::take();
        let opts = RenderOptions { width: 64, height: 64, samples, ..Default::default() };
        let scene = match umbrage_scene::load("default") {
            Ok(s) => s,
            Err(e) => {
                out.push(Group {
                    name: "Renderer (default scene)".into(),
                    creations: Vec::new(),
                    error: Some(e.to_string()),
                    not_attempted: None,
                });
                ctx = Some(c);
                break;
            }
        };
        match Renderer::new(c, scene, opts) {
            Ok(r) => {
                ctx = Some(r.into_context());
                out.push(Group {
                    name: format!("Renderer {samples}x (default scene)"),
                    creations: creation::take(),
                    error: None,
                    not_attempted: None,
                });
            }
            Err(e) => out.push(Group {
                name: format!("Renderer {samples}x (default scene)"),
                creations: creation::take(),
                error: Some(e.to_string()),
                not_attempted: None,
            }),
        }
    }
    creation::record(false);
    (out, ctx)
}

/// The report: a line per pipeline, a summary per group, the slowest creations.
pub fn print(device: &str, groups: &[Group]) -> bool {
    let mut ok = true;
    let mut all: Vec<(&str, &Creation)> = Vec::new();
    println!("pipelines on {device}: creation time of each (vkCreate*Pipelines), nothing recorded");
    for g in groups {
        if let Some(why) = &g.not_attempted {
            println!("{}: not attempted ({why})", g.name);
            continue;
        }
        let total: f64 = g.creations.iter().map(|c| c.ms).sum();
        println!("{} ({} pipelines, {total:.1} ms)", g.name, g.creations.len());
        for c in &g.creations {
            match &c.error {
                None => println!("  {:>9.1} ms  {}", c.ms, c.label),
                Some(e) => {
                    ok = false;
                    println!("  {:>9.1} ms  {}  FAILED: {e}", c.ms, c.label);
                }
            }
            all.push((&g.name, c));
        }
        if let Some(e) = &g.error {
            ok = false;
            println!("  FAILED: {e}");
        }
    }
    all.sort_by(|a, b| b.1.ms.total_cmp(&a.1.ms));
    println!("slowest:");
    for (g, c) in all.iter().take(5) {
        println!("  {:>9.1} ms  {}  ({g})", c.ms, c.label);
    }
    let n: usize = groups.iter().map(|g| g.creations.len()).sum();
    let total: f64 = groups.iter().flat_map(|g| &g.creations).map(|c| c.ms).sum();
    println!("{n} pipelines created in {total:.1} ms; {}", if ok { "all created" } else { "FAILURES above" });
    ok
}
