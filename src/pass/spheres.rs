//! Analytic sphere casters in the pass: per frame and light, the volume of the sphere's
//! tangency circle as an n-gon ([`geom::sphere`](crate::geom::sphere)), streamed as naive
//! vertices (`w = 1` on the circle's polygon, `w = 0` extruded by the volume shader) into
//! the slot's stream and drawn with the mesh casters' pipelines: always z-fail with the light
//! cap (the flat polygon in the tangency plane, inside the sphere and so behind every visible
//! point: depth NEVER), so the count is right wherever the eye is.
//!
//! `n` is chosen per frame and light so the shadow's error stays under half a pixel
//! ([`auto_segments`]), unless fixed per sphere. With [`Technique::Planar`](super::Technique)
//! the polygon is flattened onto the receiver plane instead.

use super::desc::{IndexFormat, Technique};
use super::draw::{CasterDraw, Draw};
use super::stats::{CasterStats, SphereStats, Totals, Triangles, UsedIndexFormat};
use super::view::ShadowView;
use crate::error::{Error, Result};
use crate::geom::sphere::{auto_segments, shadow_error_px, volume_triangles, ViewScale};
use crate::geom::{Light, LightKind, Sphere};
use crate::shadow::{Case, DarkCap, VolumePath};
use ash::vk;
use glam::{DMat4, DVec4};

/// A sphere caster added to a [`ShadowPass`](super::ShadowPass) (ids are never reused).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SphereId {
    /// The pass that made it (`ShadowPass`'s process-unique id).
    pub(crate) pass: u64,
    pub(crate) n: u64,
}

/// A sphere caster as [`ShadowPass::spheres`](super::ShadowPass::spheres) lists it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereInfo<'a> {
    /// Its id.
    pub id: SphereId,
    /// The name it was added with.
    pub name: &'a str,
    /// Centre and radius, world space.
    pub sphere: Sphere,
    /// The fixed polygon size, or `None` (chosen per frame for half a pixel of error).
    pub segments: Option<u32>,
}

/// One sphere caster of the pass.
#[derive(Clone, Debug)]
pub(crate) struct SphereCaster {
    pub id: SphereId,
    pub name: String,
    pub sphere: Sphere,
    /// Fixed polygon size, or `None`: [`auto_segments`] per frame and light.
    pub segments: Option<u32>,
}

/// A light's homogeneous position in f64 (w = 0: towards the light).
pub(crate) fn light_h(light: &Light) -> DVec4 {
    match light.kind {
        LightKind::Directional => (-light.direction.as_dvec3().normalize()).extend(0.0),
        _ => light.position.as_dvec3().extend(1.0),
    }
}

/// Refuses a frame where a positional light is inside or on a sphere caster.
pub(crate) fn check(spheres: &[SphereCaster], lights: &[Light]) -> Result<()> {
    for s in spheres {
        for (li, l) in lights.iter().enumerate() {
            if s.sphere.tangency(light_h(l)).is_none() {
                return Err(Error::argument(
                    "light",
                    format!(
                        "light {li} at {} is inside or on sphere caster '{}' (centre {}, radius {}): no tangent cone exists",
                        l.position, s.name, s.sphere.center, s.sphere.radius
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The view's pixel and near-plane scale, from its projection.
pub(crate) fn view_scale(view: &ShadowView) -> ViewScale {
    let p = view.proj.as_dmat4();
    let (tx, ty) = (1.0 / p.x_axis.x.abs(), 1.0 / p.y_axis.y.abs());
    // The smallest pixel subtends `2 tan(fov/2) / h * cos²` at the image's corners.
    let cos2 = 1.0 / (1.0 + tx * tx + ty * ty);
    let pixel_angle = (2.0 * ty / view.height as f64).min(2.0 * tx / view.width as f64) * cos2;
    // Depth 0 (the near plane) on the optical axis, unprojected.
    let h = p.inverse() * DVec4::new(0.0, 0.0, 0.0, 1.0);
    let near = (-h.z / h.w).abs();
    ViewScale { eye: view.eye, pixel_angle, near: if near.is_finite() && near > 0.0 { near } else { 1e-3 } }
}

/// Appends `tris` to the stream as naive vertices (4 x f32 each), 16-aligned; returns the
/// draw.
fn stream_tris(stream: &mut Vec<u8>, tris: &[[DVec4; 3]], case: Case, light_cap: bool) -> Draw {
    while !stream.len().is_multiple_of(16) {
        stream.push(0);
    }
    let offset = stream.len() as u64;
    for v in tris.iter().flatten() {
        for f in v.as_vec4().to_array() {
            stream.extend(f.to_le_bytes());
        }
    }
    Draw {
        vertices: vk::Buffer::null(),
        kept: None,
        offset,
        count: 3 * tris.len() as u32,
        format: IndexFormat::Naive,
        case,
        light_cap,
        indirect: false,
        mesh: None,
    }
}

/// What [`pack_light`] needs besides the spheres.
pub(crate) struct SphereInput<'a> {
    pub view: &'a ShadowView,
    pub scale: ViewScale,
    pub light: &'a Light,
    pub technique: Technique,
    pub planar_receiver: DVec4,
}

/// Plans every sphere caster for one light, appending their draws and stats.
pub(crate) fn pack_light(
    spheres: &[SphereCaster],
    input: &SphereInput,
    stream: &mut Vec<u8>,
    totals: &mut Totals,
    casters: &mut Vec<CasterDraw>,
    stats: &mut Vec<CasterStats>,
) {
    let view = input.view;
    let vp_rel = view.proj.as_dmat4() * view.view.as_dmat4() * DMat4::from_translation(-view.eye);
    let l = light_h(input.light);
    let directional = l.w == 0.0;
    for s in spheres {
        let c = s.sphere.center;
        let Some(t) = s.sphere.tangency(l) else { continue };
        // Beyond a bounded light's range the sphere casts nothing it lights.
        let out_of_range = match (input.light.radius, directional) {
            (Some(r), false) => (l.truncate() - c).length() - s.sphere.radius > r as f64,
            _ => false,
        };
        let (n, auto) = match s.segments {
            Some(n) => (n, false),
            None => (auto_segments(&s.sphere, &t, l, &input.scale), true),
        };
        let error_px = shadow_error_px(&s.sphere, &t, l, &input.scale, n);
        let (volume, cap) = volume_triangles(&t, n, directional, c);
        let light_object = if directional { l } else { (l.truncate() - c).extend(1.0) };
        let mut tris = Triangles::default();
        let (case, draws, mvp) = if out_of_range {
            (Case::Culled, Vec::new(), vp_rel * DMat4::from_translation(c))
        } else if input.technique == Technique::Planar {
            // Flattened onto the receiver plane from the light: M = (p·L) I - L pᵀ.
            let p = input.planar_receiver;
            let pl = p.dot(l);
            if pl > 0.0 {
                let m = DMat4::from_diagonal(DVec4::splat(pl)) - DMat4::from_cols(l * p.x, l * p.y, l * p.z, l * p.w);
                tris.sides = cap.len() as u64;
                (Case::ZPass, vec![stream_tris(stream, &cap, Case::ZPass, false)], vp_rel * m * DMat4::from_translation(c))
            } else {
                (Case::Culled, Vec::new(), vp_rel * DMat4::from_translation(c))
            }
        } else {
            tris.sides = if directional { n as u64 } else { 2 * n as u64 };
            tris.dark_cap = (volume.len() as u64).saturating_sub(tris.sides);
            tris.light_cap = cap.len() as u64;
            let draws =
                vec![stream_tris(stream, &volume, Case::ZFailLightCap, false), stream_tris(stream, &cap, Case::ZFailLightCap, true)];
            (Case::ZFailLightCap, draws, vp_rel * DMat4::from_translation(c))
        };
        let vertex_bytes: u64 = draws.iter().map(|d| d.count as u64 * 16).sum();
        totals.triangles.add(&tris);
        totals.vertex_bytes += vertex_bytes;
        match case {
            Case::Culled => totals.cases.culled += 1,
            Case::ZPass => totals.cases.zpass += 1,
            Case::ZFail => totals.cases.zfail += 1,
            Case::ZFailLightCap => totals.cases.zfail_light_cap += 1,
        }
        let ntris = tris.total();
        stats.push(CasterStats {
            name: s.name.clone(),
            case,
            silhouette_edges: if case == Case::Culled { 0 } else { n as u64 },
            triangles: tris,
            index_bytes: 0,
            vertex_bytes,
            bytes_per_triangle: if ntris > 0 { vertex_bytes as f64 / ntris as f64 } else { 0.0 },
            index_format: if case == Case::Culled { UsedIndexFormat::None } else { UsedIndexFormat::Naive },
            dark_cap_kind: if directional || input.technique == Technique::Planar { DarkCap::None } else { DarkCap::Fan },
            path: VolumePath::Sphere,
            path_reason: String::new(),
            multiplicity_max: 1,
            parts: Vec::new(),
            sphere: Some(SphereStats { segments: n, auto, error_px }),
        });
        casters.push(CasterDraw {
            case,
            mvp: mvp.as_mat4(),
            light_object: light_object.as_vec4(),
            transmittance: None,
            draws: super::draw::DrawList::Own(draws),
            edge_quad: None,
        });
    }
}

/// The index of sphere `id`.
pub(crate) fn find(spheres: &[SphereCaster], pass: u64, id: SphereId) -> Result<usize> {
    if id.pass != pass {
        return Err(crate::error::Misuse::ForeignId { what: "sphere caster", id: format!("{}", id.n), owner: id.pass, this: pass }.into());
    }
    spheres
        .iter()
        .position(|s| s.id == id)
        .ok_or_else(|| crate::error::Misuse::UnknownId { what: "sphere caster", id: format!("{}", id.n) }.into())
}

/// Rejects a sphere the pass cannot draw.
pub(crate) fn check_sphere(name: &str, sphere: &Sphere, segments: Option<u32>) -> Result<()> {
    if let Some(p) = sphere.problem() {
        return Err(Error::mesh(name, format!("sphere caster: {p}")));
    }
    if let Some(n) = segments {
        if !(3..=crate::geom::sphere::MAX_SEGMENTS).contains(&n) {
            return Err(Error::mesh(
                name,
                format!("sphere caster: segments must be in [3, {}], got {n}", crate::geom::sphere::MAX_SEGMENTS),
            ));
        }
    }
    Ok(())
}
