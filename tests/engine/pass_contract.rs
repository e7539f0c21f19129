//! `ShadowPass`'s contract with its host, as an engine developer meets it: creation options
//! checked against the device (sample counts, the render-pass target, depth clamp with
//! reverse-Z), and recording misuse (a light out of range, another pass's frame, a stale frame,
//! a target of the wrong size or layout, a render-pass call order) refused with a typed error
//! before anything is recorded. Validation is on; any message fails.

use crate::common;

use ash::vk;
use glam::{DMat4, DVec3, Mat4, Vec3};
use umbrage::error::Misuse;
use umbrage::geom::{Camera, Light};
use umbrage::pass::{
    DepthDirection, DepthMode, DepthStencilTarget, EnabledFeatures, PassSettings, RenderPassTarget, ShadowPass, ShadowPassDesc, ShadowView,
    TargetModel, Technique,
};
use umbrage::Error;
use umbrage_scene::shapes;

const SIZE: (u32, u32) = (160, 120);

fn pass(ctx: &umbrage::gpu::Context, desc: &ShadowPassDesc) -> umbrage::Result<ShadowPass> {
    ShadowPass::new(&ctx.instance, ctx.physical, &ctx.device, (*ctx.allocator).clone(), desc)
}

fn desc(ctx: &umbrage::gpu::Context) -> ShadowPassDesc {
    ShadowPassDesc { depth_stencil_format: ctx.depth_format, ..Default::default() }
}

fn view() -> ShadowView {
    let cam = Camera { eye: Vec3::new(0.0, 3.0, 6.0), target: Vec3::ZERO, ..Default::default() };
    let view = glam::camera::rh::view::look_at_mat4(cam.eye, cam.target, cam.up);
    ShadowView::from_view_matrix(cam.eye.as_dvec3(), view, cam.proj_infinite(4.0 / 3.0), SIZE).unwrap()
}

fn light() -> Light {
    Light::point(Vec3::new(1.0, 5.0, 2.0))
}

fn misuse(r: umbrage::Result<()>) -> Misuse {
    match r {
        Err(Error::Misuse(m)) => m,
        other => panic!("expected a Misuse error, got {other:?}"),
    }
}

/// A render pass with one subpass: optionally a colour attachment, optionally a depth-stencil
/// attachment of `format` and `samples`, in DEPTH_STENCIL_ATTACHMENT_OPTIMAL (or read-only).
fn render_pass(
    ctx: &umbrage::gpu::Context,
    format: vk::Format,
    samples: vk::SampleCountFlags,
    depth_stencil: Option<vk::ImageLayout>,
) -> (vk::RenderPass, umbrage::Result<RenderPassTarget>) {
    let attachments = [
        vk::AttachmentDescription::default()
            .format(vk::Format::R8G8B8A8_UNORM)
            .samples(samples)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .final_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL),
        vk::AttachmentDescription::default()
            .format(format)
            .samples(samples)
            .load_op(vk::AttachmentLoadOp::LOAD)
            .stencil_load_op(vk::AttachmentLoadOp::LOAD)
            .initial_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
            .final_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL),
    ];
    let color = [vk::AttachmentReference { attachment: 0, layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL }];
    let ds = vk::AttachmentReference { attachment: 1, layout: depth_stencil.unwrap_or(vk::ImageLayout::UNDEFINED) };
    let mut subpass = vk::SubpassDescription::default().pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS).color_attachments(&color);
    if depth_stencil.is_some() {
        subpass = subpass.depth_stencil_attachment(&ds);
    }
    let subpasses = [subpass];
    let n = if depth_stencil.is_some() { 2 } else { 1 };
    let info = vk::RenderPassCreateInfo::default().attachments(&attachments[..n]).subpasses(&subpasses);
    // SAFETY: a well-formed create info on the context's device; destroyed by the caller.
    let rp = unsafe { ctx.device.create_render_pass(&info, None) }.expect("vkCreateRenderPass");
    // SAFETY: `info` is the create info `rp` was made from, its pointers alive.
    let target = unsafe { RenderPassTarget::new(rp, &info, 0) };
    (rp, target)
}

#[test]
fn creation_options_are_checked_against_the_device() {
    let Some(ctx) = common::context() else { return };
    // Sample counts: not 1/2/4/8 is an invalid desc; otherwise accepted exactly when the
    // device's framebuffer limits and the format both have the count.
    for n in [0, 3, 16] {
        match pass(&ctx, &ShadowPassDesc { samples: n, ..desc(&ctx) }) {
            Err(Error::InvalidDesc { field, .. }) => assert_eq!(field, "ShadowPassDesc::samples"),
            other => panic!("{n} samples: {:?}", other.err()),
        }
    }
    let mut p = pass(&ctx, &desc(&ctx)).expect("a default pass");
    let before = p.settings();
    // Ray query without the host enabling it (EnabledFeatures::ray_query is off here): a clear
    // error naming the extension, at creation and between frames.
    let settings = PassSettings { technique: Technique::RayQuery, ..Default::default() };
    match pass(&ctx, &ShadowPassDesc { settings, ..desc(&ctx) }) {
        Err(Error::Unsupported(msg)) => assert!(msg.contains("VK_KHR_ray_query") && msg.contains("EnabledFeatures::ray_query"), "{msg}"),
        other => panic!("ray query accepted at creation without the feature: {:?}", other.err()),
    }
    assert!(matches!(p.set_settings(settings), Err(Error::Unsupported(_))), "ray query accepted between frames");
    assert_eq!(p.settings(), before);
    // SAFETY: plain queries on the context's physical device.
    let (limits, image_counts) = unsafe {
        let limits = ctx.instance.get_physical_device_properties(ctx.physical).limits;
        let image = ctx.instance.get_physical_device_image_format_properties(
            ctx.physical,
            ctx.depth_format,
            vk::ImageType::TYPE_2D,
            vk::ImageTiling::OPTIMAL,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
            vk::ImageCreateFlags::empty(),
        );
        (limits, image.map(|p| p.sample_counts).unwrap_or_default())
    };
    let supported = limits.framebuffer_depth_sample_counts & limits.framebuffer_stencil_sample_counts & image_counts;
    let mut refused = 0;
    for n in [1u32, 2, 4, 8] {
        let expected = supported.as_raw() & n != 0;
        match pass(&ctx, &ShadowPassDesc { samples: n, ..desc(&ctx) }) {
            Ok(_) => assert!(expected, "{n} samples accepted, but the device lacks them"),
            Err(e) => {
                assert!(!expected, "{n} samples refused, but the device has them: {e}");
                assert!(matches!(e, Error::Unsupported(_)) && e.to_string().contains("samples"), "{e}");
                refused += 1;
            }
        }
    }
    eprintln!("sample counts {:?}: {refused} of 2, 4, 8 refused", supported);

    // A finite far plane (depth clamp), forward or reverse-Z, without depthClamp enabled.
    for direction in [DepthDirection::Forward, DepthDirection::Reverse] {
        let d = ShadowPassDesc {
            depth_mode: DepthMode::Clamp,
            depth_direction: direction,
            features: EnabledFeatures { depth_clamp: false, ..Default::default() },
            ..desc(&ctx)
        };
        let e = pass(&ctx, &d).err().expect("refused");
        assert!(matches!(e, Error::Unsupported(_)) && e.to_string().contains("depthClamp"), "{direction:?}: {e}");
        assert!(!e.to_string().contains("--"), "a library message names a CLI flag: {e}");
    }
    if common::feature(ctx.features.depth_clamp, "depthClamp") {
        let d = ShadowPassDesc {
            depth_mode: DepthMode::Clamp,
            depth_direction: DepthDirection::Reverse,
            features: EnabledFeatures { depth_clamp: true, ..Default::default() },
            ..desc(&ctx)
        };
        pass(&ctx, &d).expect("reverse-Z with a clamped far plane where depthClamp is enabled");
    }

    // The render-pass target: a subpass without a depth-stencil attachment, or with a
    // read-only one, is refused; a format or sample count other than the desc's too.
    let (rp, t) = render_pass(&ctx, ctx.depth_format, vk::SampleCountFlags::TYPE_1, None);
    assert!(matches!(t, Err(Error::InvalidDesc { .. })), "no depth-stencil attachment: {:?}", t.err());
    let mut render_passes = vec![rp];
    let (rp, t) = render_pass(&ctx, ctx.depth_format, vk::SampleCountFlags::TYPE_1, Some(vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL));
    assert!(t.is_err(), "a read-only depth-stencil attachment is accepted");
    render_passes.push(rp);
    let (rp, t) =
        render_pass(&ctx, ctx.depth_format, vk::SampleCountFlags::TYPE_4, Some(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL));
    render_passes.push(rp);
    let target = TargetModel::RenderPass(t.expect("a 4-sample subpass"));
    match pass(&ctx, &ShadowPassDesc { target, ..desc(&ctx) }) {
        Err(Error::InvalidDesc { field, msg }) => assert!(field == "ShadowPassDesc::target" && msg.contains("samples"), "{msg}"),
        other => panic!("1-sample desc for a 4-sample subpass: {:?}", other.err()),
    }
    let other_format =
        if ctx.depth_format == vk::Format::D24_UNORM_S8_UINT { vk::Format::D32_SFLOAT_S8_UINT } else { vk::Format::D24_UNORM_S8_UINT };
    let (rp, t) = render_pass(&ctx, other_format, vk::SampleCountFlags::TYPE_1, Some(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL));
    render_passes.push(rp);
    let target = TargetModel::RenderPass(t.expect("a D24S8/D32S8 subpass"));
    assert!(matches!(pass(&ctx, &ShadowPassDesc { target, ..desc(&ctx) }), Err(Error::InvalidDesc { .. })), "format mismatch accepted");
    let (rp, t) =
        render_pass(&ctx, ctx.depth_format, vk::SampleCountFlags::TYPE_1, Some(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL));
    render_passes.push(rp);
    let target = TargetModel::RenderPass(t.expect("a valid subpass"));
    let transmit = ShadowPassDesc { target, transmit_format: Some(vk::Format::R16G16B16A16_SFLOAT), ..desc(&ctx) };
    assert!(matches!(pass(&ctx, &transmit), Err(Error::InvalidDesc { .. })), "colour targets in the render-pass model accepted");
    {
        // The valid one: built against the host's subpass; an upload not recorded before the
        // render pass is an ordering error, not a validation error.
        let mut p = pass(&ctx, &ShadowPassDesc { target, ..desc(&ctx) }).expect("a render-pass pass");
        p.add_caster("cube", &shapes::cuboid(Vec3::ONE), DMat4::IDENTITY).unwrap();
        let f = p.prepare(0, &view(), &[light()]).unwrap();
        let t = DepthStencilTarget::new(vk::Image::null(), vk::ImageView::null(), vk::Extent2D { width: SIZE.0, height: SIZE.1 });
        let mut result = None;
        ctx.one_shot(|cb| {
            // SAFETY: the pass refuses before recording (the upload is pending).
            result = Some(unsafe { p.cmd_determine(cb, &f, 0, &t) });
        })
        .unwrap();
        assert!(matches!(misuse(result.unwrap()), Misuse::Order(_)));
    }
    for rp in render_passes {
        // SAFETY: no pass built on these render passes is alive, nothing recorded uses them.
        unsafe { ctx.device.destroy_render_pass(rp, None) };
    }
    ctx.check_validation().unwrap();
}

#[test]
fn recording_misuse_is_a_typed_error_before_anything_is_recorded() {
    let Some(ctx) = common::context() else { return };
    let mut p = pass(&ctx, &desc(&ctx)).unwrap();
    let mut q = pass(&ctx, &desc(&ctx)).unwrap();
    let cube = shapes::cuboid(Vec3::ONE);
    p.add_caster("cube", &cube, DMat4::from_translation(DVec3::new(0.0, 1.0, 0.0))).unwrap();
    q.add_caster("cube", &cube, DMat4::IDENTITY).unwrap();
    let extent = vk::Extent2D { width: SIZE.0, height: SIZE.1 };
    // Null handles: every check below fails before the pass would touch them.
    let target = DepthStencilTarget::new(vk::Image::null(), vk::ImageView::null(), extent);
    let stale = p.prepare(0, &view(), &[light()]).unwrap();
    let frame = p.prepare(0, &view(), &[light()]).unwrap();
    let foreign = q.prepare(1, &view(), &[light()]).unwrap();
    let mut results = Vec::new();
    ctx.one_shot(|cb| {
        // SAFETY: every call is refused before recording (the assertions below check it);
        // `cb` is a recording command buffer of the context's device.
        unsafe {
            results.push(("light out of range", p.cmd_determine(cb, &frame, 1, &target)));
            results.push(("light state out of range", p.cmd_light_state(cb, &frame, 5, extent)));
            results.push(("stale frame", p.cmd_determine(cb, &stale, 0, &target)));
            results.push(("stale upload", p.cmd_before_rendering(cb, &stale)));
            results.push(("another pass's frame", p.cmd_determine(cb, &foreign, 0, &target)));
            results.push(("another pass's upload", p.cmd_upload(cb, &foreign)));
            let small = DepthStencilTarget::new(vk::Image::null(), vk::ImageView::null(), vk::Extent2D { width: 80, height: 60 });
            results.push(("wrong extent", p.cmd_determine(cb, &frame, 0, &small)));
            let undefined = target.with_layouts(vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
            results.push(("UNDEFINED layout", p.cmd_determine(cb, &frame, 0, &undefined)));
        }
    })
    .unwrap();
    for (what, r) in results {
        let e = r.err().unwrap_or_else(|| panic!("{what}: accepted"));
        eprintln!("{what}: {e}");
        assert!(!e.to_string().contains("--"), "{what}: a library message names a CLI flag: {e}");
        match what {
            "light out of range" | "light state out of range" => {
                assert!(matches!(e, Error::Misuse(Misuse::LightIndex { .. })), "{what}: {e}")
            }
            "stale frame" | "stale upload" => assert!(matches!(e, Error::Misuse(Misuse::StaleFrame { .. })), "{what}: {e}"),
            "another pass's frame" | "another pass's upload" => assert!(matches!(e, Error::Misuse(Misuse::ForeignFrame)), "{what}: {e}"),
            _ => assert!(matches!(e, Error::Misuse(Misuse::Argument { .. })), "{what}: {e}"),
        }
    }
    // The sphere casters, listed by name.
    let ball = umbrage::geom::Sphere { center: DVec3::new(0.0, 1.0, 2.0), radius: 0.5 };
    let sid = p.add_sphere_caster("ball", ball, Some(32)).unwrap();
    let listed: Vec<_> = p.spheres().collect();
    assert_eq!(listed.len(), 1);
    assert_eq!((listed[0].id, listed[0].name, listed[0].sphere, listed[0].segments), (sid, "ball", ball, Some(32)));
    p.remove_sphere(sid).unwrap();
    assert_eq!(p.spheres().count(), 0);
    // An area light is refused, pointing at its expansion.
    let mut area = light();
    area.area = Some(umbrage::geom::AreaLight::new(umbrage::geom::AreaShape::Disc { radius: 0.5 }, Vec3::NEG_Y, 4));
    let Err(e) = p.prepare(1, &view(), &[area]) else { panic!("an area light accepted") };
    assert!(e.to_string().contains("expand_lights"), "{e}");
    ctx.check_validation().unwrap();
}

#[test]
fn shadow_view_from_a_view_matrix() {
    let eye = Vec3::new(1.0, 2.0, 6.0);
    let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::ZERO, Vec3::Y);
    let proj = glam::camera::rh::proj::vulkan::perspective_infinite(1.0, 1.5, 0.1);
    let v = ShadowView::from_view_matrix(eye.as_dvec3(), view, proj, (300, 200)).unwrap();
    assert_eq!(v.view.w_axis, glam::Vec4::W, "the translation is stripped");
    // The eye-relative view applied to (p - eye) is the full view applied to p.
    let p = Vec3::new(0.3, -0.7, 1.1);
    assert!((v.view.transform_point3(p - eye) - view.transform_point3(p)).length() < 1e-5);
    // A view matrix of another eye, a scaled one, and a projection passed as the view.
    for (what, bad_eye, bad_view) in [
        ("another eye", eye.as_dvec3() + DVec3::X, view),
        ("scaled", eye.as_dvec3(), Mat4::from_scale(Vec3::splat(2.0)) * view),
        ("projection", eye.as_dvec3(), proj),
    ] {
        let e = ShadowView::from_view_matrix(bad_eye, bad_view, proj, (300, 200)).err().unwrap_or_else(|| panic!("{what} accepted"));
        assert!(matches!(e, Error::Misuse(_)), "{what}: {e}");
    }
}
