//! What a frame checks before it is planned: the options the device can honour, the spheres
//! it can draw, and the pass's share of the frame settings.

use crate::options::*;
use crate::technique::{CubeFaces, RenderTechnique, ShadowMap};
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;
use umbrage::pass::PassSettings;
use umbrage_scene::Scene;

/// Spheres the frame cannot draw: the eye inside or on one (it may have moved there), or
/// casting spheres with the shadow-map baseline (its depth pass draws meshes only).
pub(super) fn check_spheres(scene: &Scene, s: &FrameSettings) -> Result<()> {
    for sp in &scene.spheres {
        if let Some(problem) = umbrage_scene::sphere_placement_problem(sp, &scene.camera, &scene.lights) {
            return Err(Error::input(format!("scene '{}'", scene.name), problem));
        }
    }
    if s.technique == RenderTechnique::Pass(Technique::RayQuery) {
        if let Some(why) = super::techniques::ray_query_unsupported(scene) {
            return Err(Error::Unsupported(why));
        }
    }
    if s.technique.shadow_map().is_some() && scene.spheres.iter().any(|s| s.casts_shadow) {
        return Err(Error::Unsupported(
            "--method shadowmap does not draw analytic sphere casters into its maps; use a shadow-volume method".into(),
        ));
    }
    Ok(())
}

/// The pass's share of the frame settings.
pub(super) fn pass_settings(s: &FrameSettings) -> PassSettings {
    PassSettings { technique: s.technique.pass(), counter: s.counter, index_format: s.index_format, toggles: s.toggles, keep: s.keep }
}

/// The options this device can honour (checked at creation and before every frame, since
/// benchmarks switch methods and counters between frames).
pub(super) fn check_options(ctx: &Context, config: &RenderConfig, s: &FrameSettings) -> Result<()> {
    let f = &ctx.features;
    if config.depth_mode == DepthMode::Clamp && !f.depth_clamp {
        return Err(Error::Unsupported("--depth-mode clamp needs the depthClamp feature; use --depth-mode infinite".into()));
    }
    if s.index_format == IndexFormat::U8 && !f.index_type_uint8 {
        return Err(Error::Unsupported("--index-format u8 needs VK_EXT_index_type_uint8; use auto or u16".into()));
    }
    if s.technique == RenderTechnique::Pass(Technique::RayQuery) && s.counter == Counter::Float {
        // The rays write the stencil; the float counter counts volumes (and would light from a
        // count image nothing wrote this frame).
        return Err(Error::InvalidDesc {
            field: "FrameSettings::counter",
            msg: "--method rayquery writes the stencil, not a volume count: use --counter stencil".into(),
        });
    }
    if s.technique == RenderTechnique::Pass(Technique::RayQuery) && !f.ray_query {
        return Err(umbrage::gpu::accel::missing_ray_query(&ctx.info.name));
    }
    if matches!(s.technique, RenderTechnique::ShadowMap(ShadowMap { cube: CubeFaces::Multiview, .. })) {
        if let Some(e) = crate::stages::shadowmap::multiview_refusal(ctx) {
            return Err(e);
        }
    }
    let shadow_map = s.technique.shadow_map().is_some();
    if (s.counter == Counter::Float || shadow_map || config.self_shadow) && !f.r32f_blend {
        return Err(Error::Unsupported(
            "--counter float, --method shadowmap and --self-shadow need R32_SFLOAT colour blending, which this device lacks; use --counter stencil".into(),
        ));
    }
    check_samples(ctx, config, s)?;
    if config.transmit_fp32 && !f.rgba32f_blend {
        return Err(Error::Unsupported(
            "--transmit log32/mul32 need R32G32B32A32_SFLOAT blending, which this device lacks; use log16".into(),
        ));
    }
    Ok(())
}

/// The multisampled frame's options ([`RenderConfig::samples`]): a count of 1, 2, 4 or 8 that
/// every target supports, `sampleRateShading`, and what renders per sample (the stencil
/// shadow-volume methods, shaded or stencil views).
fn check_samples(ctx: &Context, config: &RenderConfig, s: &FrameSettings) -> Result<()> {
    let n = config.samples;
    if !matches!(n, 1 | 2 | 4 | 8) {
        return Err(Error::InvalidDesc { field: "RenderOptions::samples", msg: format!("{n} samples; the count is 1, 2, 4 or 8") });
    }
    if n == 1 {
        return Ok(());
    }
    let f = &ctx.features;
    if f.frame_sample_counts & n == 0 {
        return Err(Error::Unsupported(format!(
            "{}: {n} samples are not supported on every target of the frame (colour, depth-stencil, sampled); supported: {}",
            ctx.info.name,
            [1u32, 2, 4, 8, 16, 32, 64]
                .iter()
                .filter(|&&c| f.frame_sample_counts & c != 0)
                .map(|c| c.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    if !f.sample_rate_shading {
        return Err(Error::Unsupported(format!("{}: a multisampled frame shades per sample and needs sampleRateShading", ctx.info.name)));
    }
    if s.capture && !f.standard_sample_locations {
        return Err(Error::Unsupported(format!(
            "{}: a multisampled capture is read back at Vulkan's standard sample locations, which this device does not use",
            ctx.info.name
        )));
    }
    let why = match (s.technique, s.counter, s.view) {
        _ if !s.technique.is_volume_pass() => Some(format!("the {} baseline", s.technique.name())),
        (_, Counter::Float, _) => Some("the float counter".to_string()),
        (_, _, View::Volumes) => Some("the volume overlay view".to_string()),
        _ => None,
    };
    match why {
        Some(what) => Err(Error::InvalidDesc {
            field: "RenderOptions::samples",
            msg: format!("{what} renders at one sample; multisampling ({n} samples) is for the stencil shadow-volume methods"),
        }),
        None => Ok(()),
    }
}
