//! The rows of `docs/contract.md`'s table, concatenated by [`super::rows`]: one function per
//! group of inputs, in the table's order.

use super::*;

/// `Light`'s fields, for each kind: point, spot, directional.
pub(super) fn light_rows() -> Vec<Row> {
    let mut rows = Vec::new();
    for kind in [LightKind::Point, LightKind::Spot, LightKind::Directional] {
        let input = match kind {
            LightKind::Point => "`Light` (point), `prepare`",
            LightKind::Spot => "`Light` (spot), `prepare`",
            _ => "`Light` (directional), `prepare`",
        };
        rows.push(Row {
            input,
            field: "Light::position",
            range: "finite",
            expect: Expect::Argument("Light::position"),
            accepted: light_probes(kind, &[Vec3::new(-1e6, 5.0, 1e6)], |l, v| l.position = v),
            refused: light_probes(kind, &[Vec3::new(NAN, 5.0, 0.0), Vec3::new(0.0, INF, 0.0)], |l, v| l.position = v),
        });
        let (range, accepted, refused): (&str, Vec<Vec3>, Vec<Vec3>) = match kind {
            LightKind::Point => ("finite (ignored)", vec![Vec3::ZERO, Vec3::new(0.0, -1e-30, 0.0)], vec![Vec3::new(NAN, 0.0, 0.0)]),
            _ => (
                "finite, non-zero (any length: normalised)",
                vec![Vec3::new(0.0, -1e-18, 0.0), Vec3::new(0.0, -1e30, 0.0)],
                vec![Vec3::ZERO, Vec3::new(NAN, -1.0, 0.0), Vec3::new(0.0, -INF, 0.0)],
            ),
        };
        rows.push(Row {
            input,
            field: "Light::direction",
            range,
            expect: Expect::Argument("Light::direction"),
            accepted: light_probes(kind, &accepted, |l, v| l.direction = v),
            refused: light_probes(kind, &refused, |l, v| l.direction = v),
        });
        rows.push(Row {
            input,
            field: "Light::color",
            range: "finite, every channel >= 0",
            expect: Expect::Argument("Light::color"),
            accepted: light_probes(kind, &[Vec3::ZERO, Vec3::new(1e30, 0.0, 2.0)], |l, v| l.color = v),
            refused: light_probes(kind, &[Vec3::new(-1e-30, 1.0, 1.0), Vec3::new(1.0, NAN, 1.0), Vec3::new(1.0, 1.0, INF)], |l, v| {
                l.color = v
            }),
        });
        rows.push(Row {
            input,
            field: "Light::intensity",
            range: "finite, >= 0",
            expect: Expect::Argument("Light::intensity"),
            accepted: light_probes(kind, &[0.0f32, 1e30], |l, v| l.intensity = v),
            refused: light_probes(kind, &[-1e-30f32, NAN, INF], |l, v| l.intensity = v),
        });
        rows.push(Row {
            input,
            field: "Light::radius",
            range: "`None` (unbounded), or finite and > 0",
            expect: Expect::Argument("Light::radius"),
            accepted: light_probes(kind, &[None, Some(1e-30f32), Some(1e30)], |l, v| l.radius = v),
            refused: light_probes(kind, &[Some(0.0f32), Some(-1.0), Some(NAN), Some(INF)], |l, v| l.radius = v),
        });
        let (range, accepted, refused): (&str, Vec<f32>, Vec<f32>) = match kind {
            LightKind::Spot => ("(0, 360] degrees", vec![1e-3, 90.0, MAX_CONE_DEG], vec![0.0, -1.0, MAX_CONE_DEG.next_up(), NAN]),
            _ => ("ignored", vec![0.0, NAN, -5.0], vec![]),
        };
        rows.push(Row {
            input,
            field: "Light::cone_deg",
            range,
            expect: Expect::Argument("Light::cone_deg"),
            accepted: light_probes(kind, &accepted, |l, v| l.cone_deg = v),
            refused: light_probes(kind, &refused, |l, v| l.cone_deg = v),
        });
        if kind == LightKind::Point {
            rows.push(Row {
                input,
                field: "Light::area",
                range: "`None` (expand area lights into point samples first: `geom::area::expand_lights`)",
                expect: Expect::Argument("Light::area"),
                accepted: light_probes(kind, &[()], |l, _| l.area = None),
                refused: light_probes(kind, &[()], |l, _| {
                    l.area =
                        Some(umbrage::geom::area::AreaLight::new(umbrage::geom::area::AreaShape::Disc { radius: 0.5 }, Vec3::NEG_Y, 8));
                }),
            });
        }
    }
    rows
}

/// `ShadowView`'s fields.
pub(super) fn view_rows() -> Vec<Row> {
    let mut rows = Vec::new();
    let input = "`ShadowView`, `prepare` (and `ShadowView::from_view_matrix`)";
    rows.push(Row {
        input,
        field: "ShadowView::eye",
        range: "finite (f64)",
        expect: Expect::Argument("ShadowView::eye"),
        accepted: view_probes(&[DVec3::new(1e9, 3.0, -1e9)], |w, v| w.eye = v),
        refused: view_probes(&[DVec3::new(f64::NAN, 0.0, 0.0), DVec3::new(0.0, f64::INFINITY, 0.0)], |w, v| w.eye = v),
    });
    rows.push(Row {
        input,
        field: "ShadowView::view",
        range: "a rotation (orthonormal to 1e-4, determinant > 0) without translation",
        expect: Expect::Argument("ShadowView::view"),
        accepted: view_probes(&[Mat4::IDENTITY, Mat4::from_rotation_y(2.0)], |w, v| w.view = v),
        refused: view_probes(
            &[
                Mat4::from_scale(Vec3::splat(2.0)),
                Mat4::from_scale(Vec3::new(1.0, 1.0, -1.0)),
                Mat4::from_translation(Vec3::X),
                Mat4::from_cols_array(&[NAN; 16]),
            ],
            |w, v| w.view = v,
        ),
    });
    rows.push(Row {
        input,
        field: "ShadowView::proj",
        range: "finite, invertible (the pass's depth mode and direction)",
        expect: Expect::Argument("ShadowView::proj"),
        accepted: view_probes(&[glam::camera::rh::proj::vulkan::perspective_infinite(0.5, 1.0, 1e-3)], |w, v| w.proj = v),
        refused: view_probes(&[Mat4::ZERO, Mat4::from_cols_array(&[INF; 16])], |w, v| w.proj = v),
    });
    for field in ["ShadowView::width", "ShadowView::height"] {
        let set: fn(&mut ShadowView, u32) = if field.ends_with("width") { |w, v| w.width = v } else { |w, v| w.height = v };
        rows.push(Row {
            input,
            field,
            range: "1..=65536 (`MAX_TARGET_SIZE`)",
            expect: Expect::Argument(field),
            accepted: view_probes(&[1u32, MAX_TARGET_SIZE], set),
            refused: view_probes(&[0u32, MAX_TARGET_SIZE + 1], set),
        });
    }
    rows
}

/// `ShadowPassDesc`'s fields (the depth-stencil format accepted: `ctx`'s).
pub(super) fn desc_rows(ctx: &Context) -> Vec<Row> {
    let mut rows = Vec::new();
    let input = "`ShadowPassDesc`, `ShadowPass::new` (and `capabilities_for`)";
    rows.push(Row {
        input,
        field: "ShadowPassDesc::frames_in_flight",
        range: "1..=64",
        expect: Expect::Desc("ShadowPassDesc::frames_in_flight"),
        accepted: desc_probes(&[1usize, 64], |d, v| d.frames_in_flight = v),
        refused: desc_probes(&[0usize, 65], |d, v| d.frames_in_flight = v),
    });
    rows.push(Row {
        input,
        field: "ShadowPassDesc::samples",
        range: "1, 2, 4 or 8 (and the device's count for the format: `Error::Unsupported`)",
        expect: Expect::Desc("ShadowPassDesc::samples"),
        accepted: desc_probes(&[1u32], |d, v| d.samples = v),
        refused: desc_probes(&[0u32, 3, 16], |d, v| d.samples = v),
    });
    rows.push(Row {
        input,
        field: "ShadowPassDesc::depth_stencil_format",
        range: "D16_UNORM_S8_UINT, D24_UNORM_S8_UINT or D32_SFLOAT_S8_UINT (and an attachment format on the device: `Error::Unsupported`)",
        expect: Expect::Unsupported("8 stencil bits"),
        accepted: desc_probes(&[ctx.depth_format], |d, v| d.depth_stencil_format = v),
        refused: desc_probes(&[ash::vk::Format::D32_SFLOAT, ash::vk::Format::S8_UINT, ash::vk::Format::R8G8B8A8_UNORM], |d, v| {
            d.depth_stencil_format = v
        }),
    });
    let blendable = ash::vk::Format::R16G16B16A16_SFLOAT;
    for field in ["ShadowPassDesc::transmit_format", "ShadowPassDesc::debug_color_format"] {
        let set: fn(&mut ShadowPassDesc, Option<ash::vk::Format>) =
            if field.contains("transmit") { |d, v| d.transmit_format = v } else { |d, v| d.debug_color_format = v };
        rows.push(Row {
            input,
            field,
            range: "`None`, or a blendable colour attachment format on the device (dynamic rendering only)",
            expect: Expect::Desc(field),
            accepted: desc_probes(&[None, Some(blendable)], set),
            refused: desc_probes(&[Some(ash::vk::Format::D32_SFLOAT), Some(ash::vk::Format::R32_UINT)], set),
        });
    }
    rows.push(Row {
        input,
        field: "ShadowPassDesc::depth_mode",
        range: "`Infinite`; `Clamp` where the device has `depthClamp` and the host enabled it",
        expect: Expect::Unsupported("depthClamp"),
        accepted: desc_probes(&[DepthMode::Infinite], |d, v| d.depth_mode = v),
        refused: desc_probes(&[DepthMode::Clamp], |d, v| {
            d.depth_mode = v;
            d.features.depth_clamp = false;
        }),
    });
    rows
}

/// `PassSettings`' fields and toggles.
pub(super) fn settings_rows() -> Vec<Row> {
    let mut rows = Vec::new();
    let input = "`PassSettings`, `set_settings` (and `ShadowPass::new`)";
    rows.push(Row {
        input,
        field: "PassSettings::technique",
        range: "every `Technique` (the type holds only what a pass runs); `Mesh` and `RayQuery` where the host enabled their features",
        expect: Expect::Unsupported("EnabledFeatures::"),
        accepted: settings_probes(
            &[Technique::Volumes(Method::McGuire), Technique::EdgeQuads, Technique::Planar, Technique::Compute],
            |s, v| s.technique = v,
        ),
        refused: settings_probes(&[Technique::Mesh, Technique::RayQuery], |s, v| s.technique = v),
    });
    rows.push(Row {
        input,
        field: "PassSettings::counter",
        range: "`Stencil`; `Float` where R32_SFLOAT blends, in dynamic rendering",
        expect: Expect::Unsupported("R32_SFLOAT"),
        accepted: settings_probes(&[Counter::Stencil], |s, v| s.counter = v),
        refused: vec![],
    });
    rows.push(Row {
        input,
        field: "PassSettings::index_format",
        range: "`Auto`, `U16`; `U8` where the host enabled `indexTypeUint8`",
        expect: Expect::Unsupported("indexTypeUint8"),
        accepted: settings_probes(&[IndexFormat::Auto, IndexFormat::U16], |s, v| s.index_format = v),
        refused: settings_probes(&[IndexFormat::U8], |s, v| s.index_format = v),
    });
    // (the harness's pass enables none of the indirect-draw features)
    let compute_draws = |s: &mut PassSettings, v: ComputeDraws| {
        s.technique = Technique::Compute;
        s.toggles.compute_draws = v;
    };
    rows.push(Row {
        input,
        field: "PassToggles::compute_draws",
        range: "`Auto`, `PerChunk`; with `Technique::Compute`, `PerRecord` where the host enabled `drawIndirectFirstInstance`, \
                `Multi` with `multiDrawIndirect` too, `Count` with Vulkan 1.2's `drawIndirectCount` too",
        expect: Expect::Unsupported("drawIndirectFirstInstance"),
        accepted: settings_probes(&[ComputeDraws::Auto, ComputeDraws::PerChunk], compute_draws),
        refused: settings_probes(&[ComputeDraws::PerRecord, ComputeDraws::Multi, ComputeDraws::Count], compute_draws),
    });
    rows
}

/// A caster's mesh: its positions and triangles, and its transform.
pub(super) fn mesh_rows() -> Vec<Row> {
    let mut rows = Vec::new();
    let cube = shapes::cuboid(Vec3::ONE);
    let with_pos = |i: usize, p: Vec3| {
        let mut m = shapes::cuboid(Vec3::ONE);
        m.positions[i] = p;
        m
    };
    let big = shapes::sphere(1.0, 400, 200);
    rows.push(Row {
        input: "`Mesh`, `add_caster` / `add_transparent_caster` / `update_positions`",
        field: "Mesh::positions",
        range: "finite; any count (chunks of at most 65,535 vertices for 16-bit indices are made by the pass)",
        expect: Expect::Mesh("non-finite"),
        accepted: mesh_probes(vec![("a cube", cube.clone()), ("80,000 vertices", big)]),
        refused: mesh_probes(vec![("a NaN", with_pos(7, Vec3::new(0.0, NAN, 0.0))), ("an infinity", with_pos(0, Vec3::splat(INF)))]),
    });
    let mut out_of_range = cube.clone();
    out_of_range.triangles.last_mut().unwrap()[2] = out_of_range.positions.len() as u32;
    rows.push(Row {
        input: "`Mesh`, `add_caster` / `add_transparent_caster` / `update_positions`",
        field: "Mesh::triangles",
        range: "at least one; every index < the vertex count (degenerate and zero-area triangles are kept and harmless)",
        expect: Expect::Mesh("triangle"),
        accepted: mesh_probes(vec![("a cube", cube.clone())]),
        refused: mesh_probes(vec![
            ("an index one past the end", out_of_range),
            ("no triangles", Mesh { positions: cube.positions.clone(), triangles: vec![] }),
        ]),
    });
    rows.push(Row {
        input: "transform (`DMat4`), `add_caster` / `set_transform` / `add_transparent_caster`",
        field: "transform",
        range: "finite, determinant != 0 (mirroring allowed)",
        expect: Expect::Mesh("transform"),
        accepted: transform_probes(vec![
            ("identity", DMat4::IDENTITY),
            ("a mirror", DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0))),
            ("1e-6 scale", DMat4::from_scale(DVec3::splat(1e-6))),
        ]),
        refused: transform_probes(vec![
            ("singular", DMat4::from_scale(DVec3::new(1.0, 0.0, 1.0))),
            ("a NaN", DMat4::from_translation(DVec3::new(f64::NAN, 0.0, 0.0))),
        ]),
    });
    rows
}

/// Sphere casters and transparent casters' transmittance.
pub(super) fn sphere_and_transmittance_rows() -> Vec<Row> {
    let mut rows = Vec::new();
    let s = |c: DVec3, r: f64| Sphere { center: c, radius: r };
    rows.push(Row {
        input: "`Sphere`, `add_sphere_caster` / `set_sphere`",
        field: "Sphere::center / Sphere::radius / segments",
        range: "centre finite; radius finite and > 0; segments `None` or 3..=4096",
        expect: Expect::Mesh("sphere caster"),
        accepted: sphere_probes(vec![
            ("r = 1e-6", s(DVec3::ZERO, 1e-6), None),
            ("3 segments", s(DVec3::Y, 1.0), Some(3)),
            ("4096 segments", s(DVec3::Y, 1.0), Some(4096)),
        ]),
        refused: sphere_probes(vec![
            ("r = 0", s(DVec3::ZERO, 0.0), None),
            ("r = NaN", s(DVec3::ZERO, f64::NAN), None),
            ("centre inf", s(DVec3::splat(f64::INFINITY), 1.0), None),
            ("2 segments", s(DVec3::Y, 1.0), Some(2)),
            ("4097 segments", s(DVec3::Y, 1.0), Some(4097)),
        ]),
    });
    rows.push(Row {
        input: "transmittance (`Vec3`), `add_transparent_caster` / `add_prepared_caster`",
        field: "transmittance",
        range: "each channel in [0, 1]",
        expect: Expect::Mesh("transmittance"),
        accepted: transmittance_probes(&[Vec3::ZERO, Vec3::ONE, Vec3::new(0.2, 0.5, 1.0)]),
        refused: transmittance_probes(&[Vec3::new(1.0 + 1e-6, 0.5, 0.5), Vec3::new(-1e-6, 0.5, 0.5), Vec3::new(NAN, 0.5, 0.5)]),
    });
    rows
}
