//! Files a frame turns into: PNGs, frame dumps, and the `info` report.
#![warn(missing_docs)]

use crate::FrameOutput;
use std::path::Path;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;
use umbrage_reference::dump::{write_dump, Dump, DumpLight};
use umbrage_scene::Scene;

/// Writes RGBA8 pixels as a PNG.
pub fn write_png(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
    image::save_buffer(path, rgba, width, height, image::ExtendedColorType::Rgba8)
        .map_err(|e| Error::io(path.display().to_string(), std::io::Error::other(format!("cannot write PNG: {e}"))))
}

/// Writes an 8-bit grey PNG.
pub fn write_grey_png(path: &Path, width: u32, height: u32, grey: &[u8]) -> Result<()> {
    image::save_buffer(path, grey, width, height, image::ExtendedColorType::L8)
        .map_err(|e| Error::io(path.display().to_string(), std::io::Error::other(format!("cannot write PNG: {e}"))))
}

/// The dump of a captured frame: frame.json, world.obj, positions.f32, normals.f32,
/// shadow_K.png, stencil_K.png and color.png (format in docs/formats.md). A multisampled frame
/// writes one such dump per sample, into `DIR/sample_0` … `DIR/sample_{N-1}` (each with the
/// resolved color.png).
pub fn write_frame_dump(dir: &Path, scene: &Scene, frame: &FrameOutput) -> Result<()> {
    if !frame.samples.is_empty() {
        for k in 0..frame.samples.len() {
            let sample = frame.sample(k).ok_or_else(|| Error::Internal(format!("sample {k} of the frame")))?;
            let sub = dir.join(format!("sample_{k}"));
            std::fs::create_dir_all(&sub).map_err(|e| Error::io(sub.display().to_string(), e))?;
            write_frame_dump(&sub, scene, &sample)?;
        }
        return Ok(());
    }
    if frame.positions.is_empty() {
        return Err(Error::argument("frame", "it was rendered without capture; cannot dump"));
    }
    let positions = frame.positions.iter().flatten().copied().collect();
    let normals = frame.normals.iter().flatten().copied().collect();
    let dump = scene_dump(scene, (frame.width, frame.height), positions, normals, frame.shadow_masks(scene));
    write_scene_dump(dir, scene, &dump, &frame.stencil, &frame.color)
}

/// A frame dump of `scene` as a host saw it: its per-pixel world `positions` and `normals`
/// (W·H·3, NaN for background) and per light its mask (255 lit, 0 not, 128 background).
/// `world.obj`'s triangles are the scene's opaque shadow casters, in world space.
pub fn scene_dump(scene: &Scene, (width, height): (u32, u32), positions: Vec<f32>, normals: Vec<f32>, shadow: Vec<Vec<u8>>) -> Dump {
    let triangles = scene.meshes.iter().filter(|m| m.casts_shadow && m.opacity >= 1.0).flat_map(world_triangles).collect();
    Dump {
        width,
        height,
        camera_pos: scene.camera.eye,
        lights: scene.lights.iter().map(DumpLight::from_light).collect(),
        triangles,
        positions,
        normals,
        shadow,
        spheres: scene.spheres.iter().filter(|s| s.casts_shadow).map(|s| s.sphere).collect(),
        camera: Some(scene.camera.clone()),
        extra: Default::default(),
    }
}

fn world_triangles(m: &umbrage_scene::SceneMesh) -> Vec<[glam::Vec3; 3]> {
    let xf = m.transform.as_dmat4();
    (0..m.mesh.triangles.len()).map(|t| m.mesh.triangle(t).map(|p| xf.transform_point3(p.as_dvec3()).as_vec3())).collect()
}

/// Writes `dump` ([`write_dump`]), `transparent.obj` when `scene` has transparent casters,
/// `stencil_K.png` per light and `color.png` (RGBA8, W·H·4; nothing when empty).
pub fn write_scene_dump(dir: &Path, scene: &Scene, dump: &Dump, stencil: &[Vec<u8>], color: &[u8]) -> Result<()> {
    write_dump(dir, dump)?;
    // Transparent casters attenuate rather than occlude: one group per mesh with its
    // per-surface transmittance (1 - opacity) * colour.
    let mut transparent = String::from("# umbrage: transparent shadow casters, world space\n");
    let mut nv = 0usize;
    for m in scene.meshes.iter().filter(|m| m.casts_shadow && m.opacity < 1.0) {
        let t = (1.0 - m.opacity) * m.color;
        transparent += &format!("g {}\n# transmittance {} {} {}\n", m.name.replace(char::is_whitespace, "_"), t.x, t.y, t.z);
        for tri in world_triangles(m) {
            for v in tri {
                transparent += &format!("v {} {} {}\n", v.x, v.y, v.z);
            }
            transparent += &format!("f {} {} {}\n", nv + 1, nv + 2, nv + 3);
            nv += 3;
        }
    }
    if nv > 0 {
        let path = dir.join("transparent.obj");
        std::fs::write(&path, transparent).map_err(|e| Error::io(path.display().to_string(), e))?;
    }
    for (k, s) in stencil.iter().enumerate() {
        write_grey_png(&dir.join(format!("stencil_{k}.png")), dump.width, dump.height, s)?;
    }
    if color.is_empty() {
        return Ok(());
    }
    write_png(&dir.join("color.png"), dump.width, dump.height, color)
}

/// What `umbrage info` prints: the device, its probed features and the code paths they select.
#[derive(serde::Serialize)]
pub struct InfoReport {
    /// The chosen device and driver.
    pub device: umbrage::gpu::DeviceInfo,
    /// Optional capabilities as probed.
    pub features: umbrage::gpu::Features,
    /// Whether the validation layers are on (`UMBRAGE_VALIDATION=1`).
    pub validation: bool,
    /// Feature -> the code path it selects on this device.
    pub paths: Vec<(String, String)>,
}

/// The report for the device of `ctx`.
pub fn info_report(ctx: &Context) -> InfoReport {
    let f = &ctx.features;
    let yes_no = |b: bool, y: &str, n: &str| if b { y.to_string() } else { n.to_string() };
    let paths = vec![
        (
            "dynamicRendering, synchronization2".into(),
            yes_no(
                f.dynamic_rendering && f.synchronization2,
                "present: render, bench, view and every conform configuration work",
                "missing: render, bench and view need it; conform runs its render-pass, static-state configurations",
            ),
        ),
        (
            "depthClamp".into(),
            yes_no(f.depth_clamp, "available: --depth-mode clamp (finite far plane, clamped) works", "missing: only --depth-mode infinite"),
        ),
        (
            "depthBounds".into(),
            yes_no(
                f.depth_bounds,
                "used: illumination limited to each light's depth range",
                "missing: depth bounds test skipped (scissor only)",
            ),
        ),
        (
            "VK_EXT_depth_range_unrestricted".into(),
            yes_no(
                f.depth_range_unrestricted,
                "present: not needed (the infinite projection keeps depth in [0,1])",
                "absent: not needed (the infinite projection keeps depth in [0,1])",
            ),
        ),
        (
            "indexTypeUint8".into(),
            yes_no(
                f.index_type_uint8,
                "used: 3-byte triangles for caster chunks of <= 128 vertices (--index-format auto|u8)",
                "missing: u16 indices (6 bytes per triangle)",
            ),
        ),
        ("pipelineStatisticsQuery".into(), yes_no(f.pipeline_statistics_query, "present", "missing")),
        ("occlusionQueryPrecise".into(), yes_no(f.occlusion_query_precise, "present", "missing")),
        ("timestamps".into(), yes_no(f.timestamps, "used: gpu_ms in --stats", "missing: gpu_ms omitted")),
        (
            "R32_SFLOAT blending".into(),
            yes_no(f.r32f_blend, "available: --counter float, shadow maps, --self-shadow", "missing: --counter stencil only"),
        ),
        (
            "RGBA32F blending".into(),
            yes_no(f.rgba32f_blend, "available: --transmit log32|mul32", "missing: fp16 light-intensity maps only"),
        ),
        (
            "VK_KHR_ray_query".into(),
            yes_no(
                f.ray_query,
                "used: --method rayquery (acceleration structures, one shadow ray a pixel)",
                "missing: no --method rayquery (Mesa lavapipe 25.0.7 has it: scripts/drivers.sh install 25.0.7)",
            ),
        ),
        (
            "multiview".into(),
            match (f.multiview, umbrage::gpu::quirks::multiview_defect(&ctx.info)) {
                (false, _) => "missing: --cube atlas only (a draw per cube face)".into(),
                (true, Some(_)) => "present, not used: this lavapipe loses clipped triangles in multiview; --cube atlas".into(),
                (true, None) => "available: --cube multiview (a point light's six cube faces as views of one draw)".into(),
            },
        ),
        ("depth-stencil format".into(), format!("{} (8 stencil bits, wrap increments)", f.depth_stencil_format)),
    ];
    InfoReport { device: ctx.info.clone(), features: f.clone(), validation: ctx.validation, paths }
}

/// The report as the human-readable text `umbrage info` prints.
pub fn info_text(r: &InfoReport) -> String {
    let mut s = format!(
        "device:  {} ({})\ndriver:  {} {}\nVulkan:  {}\nvalidation: {}\n",
        r.device.name,
        r.device.kind,
        r.device.driver,
        r.device.driver_info,
        r.device.api_version,
        if r.validation { "on" } else { "off (UMBRAGE_VALIDATION=1 to enable)" }
    );
    for (k, v) in &r.paths {
        s += &format!("  {k:<34} {v}\n");
    }
    s
}

/// How one caster of a scene is handled, as classified once at load.
#[derive(serde::Serialize)]
pub struct CasterInfo {
    /// The mesh's name in the scene.
    pub name: String,
    /// `manifold` (McGuire's three cases), `multiplicity` (Kim et al.) or `sphere`.
    pub path: umbrage::shadow::VolumePath,
    /// Why a caster takes the multiplicity path (empty for manifold casters).
    pub reason: String,
    /// Triangles after welding.
    pub triangles: usize,
    /// GPU chunks (pieces of at most 32768 vertices, 16-bit indices).
    pub chunks: usize,
    /// Opacity below 1: the volumes go to the light-intensity map.
    pub transparent: bool,
    /// The connected components, each planned on its own.
    pub parts: Vec<PartInfo>,
    /// For an analytic sphere caster (`path` = `sphere`; `triangles` = 0, no parts).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sphere: Option<SphereInfo>,
}

/// An analytic sphere caster in `info --scene`.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SphereInfo {
    /// Centre, world space.
    pub center: [f64; 3],
    /// Radius.
    pub radius: f64,
    /// The scene's fixed `segments`, if any.
    pub segments: Option<u32>,
    /// Per light, the polygon's segments from the scene's camera at 960x540 (the half-pixel
    /// rule, or the fixed value).
    pub segments_per_light: Vec<u32>,
    /// Per light, the rule's bound on the shadow's error with those segments, pixels.
    pub error_px_per_light: Vec<f64>,
}

/// One connected component of a caster.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PartInfo {
    /// `manifold` or `multiplicity`.
    pub path: umbrage::shadow::VolumePath,
    /// Why this part takes the multiplicity path (empty for manifold parts).
    pub reason: String,
    /// Its triangles.
    pub triangles: usize,
}

/// Classifies every shadow-casting mesh of `scene` (no GPU needed).
pub fn caster_report(scene: &Scene) -> Result<Vec<CasterInfo>> {
    let mut out = mesh_caster_report(scene)?;
    let view = umbrage::geom::sphere::ViewScale::from_camera(&scene.camera, 960, 540);
    for sp in scene.spheres.iter().filter(|s| s.casts_shadow) {
        let (mut segs, mut errs) = (Vec::new(), Vec::new());
        for l in &scene.lights {
            let h = match l.kind {
                umbrage_scene::LightKind::Directional => (-l.direction.as_dvec3().normalize()).extend(0.0),
                _ => l.position.as_dvec3().extend(1.0),
            };
            let Some(t) = sp.sphere.tangency(h) else { continue };
            let n = sp.segments.unwrap_or_else(|| umbrage::geom::sphere::auto_segments(&sp.sphere, &t, h, &view));
            segs.push(n);
            errs.push(umbrage::geom::sphere::shadow_error_px(&sp.sphere, &t, h, &view, n));
        }
        out.push(CasterInfo {
            name: sp.name.clone(),
            path: umbrage::shadow::VolumePath::Sphere,
            reason: match sp.segments {
                Some(n) => format!("analytic sphere, {n} segments"),
                None => format!("analytic sphere, segments per light at 960x540: {segs:?}"),
            },
            triangles: 0,
            chunks: 0,
            transparent: false,
            parts: Vec::new(),
            sphere: Some(SphereInfo {
                center: sp.sphere.center.to_array(),
                radius: sp.sphere.radius,
                segments: sp.segments,
                segments_per_light: segs,
                error_px_per_light: errs,
            }),
        });
    }
    Ok(out)
}

fn mesh_caster_report(scene: &Scene) -> Result<Vec<CasterInfo>> {
    scene
        .meshes
        .iter()
        .filter(|m| m.casts_shadow)
        .map(|m| {
            let c = m.caster()?;
            Ok(CasterInfo {
                name: c.name.clone(),
                path: c.kind.path(),
                reason: match &c.kind {
                    umbrage::shadow::CasterKind::Multiplicity { reason } => reason.clone(),
                    _ => String::new(),
                },
                triangles: c.triangle_count,
                chunks: c.chunks.len(),
                transparent: c.transmittance.is_some(),
                parts: c
                    .parts
                    .iter()
                    .map(|p| PartInfo {
                        path: p.kind.path(),
                        reason: match &p.kind {
                            umbrage::shadow::CasterKind::Multiplicity { reason } => reason.clone(),
                            _ => String::new(),
                        },
                        triangles: p.triangles.len(),
                    })
                    .collect(),
                sphere: None,
            })
        })
        .collect()
}

/// One light of `umbrage info --scene`: what it is and how many point lights render it.
#[derive(Clone, Debug, serde::Serialize)]
pub struct LightInfo {
    /// `point`, `spot`, `directional` or `area`.
    pub kind: String,
    /// An area light's shape: `disc` or `rect`.
    pub shape: Option<String>,
    /// An area light's size: `[radius]` for a disc, `[width, height]` for a rectangle.
    pub size: Option<Vec<f32>>,
    /// The point lights it is rendered as (an area light's `samples`; 1 otherwise), each with
    /// its own determination (its own scissor and depth bounds) and illumination pass.
    pub point_lights: u32,
    /// Position (the centre of an area light), world space; absent for a directional light.
    pub position: Option<[f32; 3]>,
}

/// Describes every light of `scene` (no GPU needed).
pub fn light_report(scene: &Scene) -> Vec<LightInfo> {
    use umbrage::geom::AreaShape;
    use umbrage_scene::LightKind;
    scene
        .lights
        .iter()
        .map(|l| {
            let (kind, shape, size, n) = match (&l.area, l.kind) {
                (Some(a), _) => {
                    let (s, v) = match a.shape {
                        AreaShape::Disc { radius } => ("disc", vec![radius]),
                        AreaShape::Rect { width, height } => ("rect", vec![width, height]),
                    };
                    ("area", Some(s.to_string()), Some(v), a.samples)
                }
                (None, LightKind::Point) => ("point", None, None, 1),
                (None, LightKind::Spot) => ("spot", None, None, 1),
                (None, LightKind::Directional) => ("directional", None, None, 1),
            };
            LightInfo {
                kind: kind.into(),
                shape,
                size,
                point_lights: n,
                position: (l.kind != LightKind::Directional).then(|| l.position.to_array()),
            }
        })
        .collect()
}
