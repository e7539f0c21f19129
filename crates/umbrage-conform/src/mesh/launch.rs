//! `mesh.group_counts` and `mesh.task_payload`: what `vkCmdDrawMeshTasksEXT` launches (the
//! module doc says what each holds).

use super::rig::{Draw, PipeState, Rig};
use super::{pixels, Push, F_NO_TILES};
use crate::CheckResult;
use ash::vk;
use serde_json::json;
use std::time::Instant;
use umbrage::error::Result;
use umbrage::gpu::Context;

/// A tile's side in pixels (`conform_mesh.wgsl`'s TILE).
const TILE: u32 = 4;
/// `groups`' header words: num_workgroups x, y, z, workgroups, invocations.
const HEADER: usize = 5;
/// `groups`' invocations a workgroup.
const GROUP_WG: u32 = 4;
/// `spawn`'s invocations a workgroup, and `spawned`'s slots per task workgroup.
const SPAWN_WG: u32 = 32;
const SPAWN_SLOTS: usize = 9;
/// The most workgroups one draw of `--method mesh` launches (`pass::mesh::MAX_TASKS`).
const MAX_GROUPS: u32 = 65_535;

/// A workgroup id packed as the shader packs it (x in bits 0..16, y in 16..24, z in 24..32).
fn pack(x: u32, y: u32, z: u32) -> u32 {
    x | (y << 16) | (z << 24)
}

/// The expected stencil of a `width` x `height` image with tiles `tiles` (tile coordinates)
/// each counted once.
fn tiles_image((width, height): (u32, u32), tiles: &[(u32, u32)]) -> Vec<u8> {
    let mut img = vec![0u8; (width * height) as usize];
    for &(tx, ty) in tiles {
        for y in ty * TILE..(ty + 1) * TILE {
            for x in tx * TILE..(tx + 1) * TILE {
                img[(y * width + x) as usize] += 1;
            }
        }
    }
    img
}

/// Compares words `range` of `got` with `want`: the mismatches and the first three described;
/// the failure images `<name>.expected`, `.actual`, `.diff` ([`crate::value_images::words`])
/// when any differ.
fn word_mismatches(got: &[u32], want: &[u32], range: std::ops::Range<usize>, name: &str) -> (usize, Vec<String>) {
    let base = range.start;
    let bad: Vec<usize> = range.clone().filter(|&i| got[i] != want[i]).collect();
    if !bad.is_empty() {
        crate::value_images::words(name, &want[range.clone()], &got[range]);
    }
    let first = bad.iter().take(3).map(|&i| format!("{name}[{}] = {:#x}, want {:#x}", i - base, got[i], want[i])).collect();
    (bad.len(), first)
}

/// Stencil bytes that differ: (count, the first described); the failure images
/// ([`crate::image_sink::stencil_mismatch`]) when any differ.
fn image_mismatches(got: &[u8], want: &[u8], width: u32) -> (usize, Option<String>) {
    let bad: Vec<usize> = (0..want.len()).filter(|&i| got[i] != want[i]).collect();
    if !bad.is_empty() {
        let height = want.len() as u32 / width;
        crate::image_sink::stencil_mismatch(width, height, want, &vec![true; want.len()], got);
    }
    let first = bad.first().map(|&i| format!("({}, {}): {}, want {}", i as u32 % width, i as u32 / width, got[i], want[i]));
    (bad.len(), first)
}

/// `groups`' records of one draw of `n` = (x, y, z) workgroups, from word `at` of `w`.
fn groups_model(w: &mut [u32], at: usize, [x, y, z]: [u32; 3]) {
    let launched = x * y * z;
    w[at..at + HEADER].copy_from_slice(&[x, y, z, launched, launched * GROUP_WG]);
    for g in 0..launched {
        let k = at + HEADER + 2 * g as usize;
        w[k] = GROUP_WG;
        w[k + 1] = pack(g % x, g / x % y, g / (x * y)) + 1;
    }
}

/// `mesh.group_counts`.
pub fn group_counts(ctx: &Context) -> Result<CheckResult> {
    let format = ctx.depth_format;
    let size = (32u32, 28u32);
    let shape = [7u32, 3, 2];
    let (a, zero, big) = (0usize, 96usize, 128usize);
    let total = big + HEADER + 2 * MAX_GROUPS as usize;
    let mut rig = Rig::new(ctx, &[], &[], total)?;
    let both = PipeState::stencil(vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::INCREMENT_AND_WRAP);
    let pipeline = rig.pipeline(None, c"groups", format, both)?;
    let mvp = pixels(size.0, size.1);
    let draw = |flags, rec: usize, groups| Draw { pipeline, push: Push::new(mvp, [0.0; 4], flags, (0, 0, rec as u32)), groups, ops: None };
    let draws = [draw(0, a, shape), draw(0, zero, [0, 1, 1]), draw(0, zero, [2, 0, 1]), draw(F_NO_TILES, big, [MAX_GROUPS, 1, 1])];
    let t0 = Instant::now();
    let got = rig.render(format, size, (0.0, 0), &draws)?;
    let seconds = t0.elapsed().as_secs_f64();
    let mut want = vec![0u32; total];
    groups_model(&mut want, a, shape);
    groups_model(&mut want, big, [MAX_GROUPS, 1, 1]);
    // The test seam (`value_images::skewed`): one workgroup more in the first draw's header.
    want[a + 3] += u32::from(crate::value_images::skewed());
    let launched = (shape[0] * shape[1] * shape[2]) as usize;
    let parts = [
        ("draw_7x3x2", a..a + HEADER + 2 * launched),
        ("between", a + HEADER + 2 * launched..zero),
        ("zero_draws", zero..big),
        ("draw_65535", big..total),
    ];
    let mut numbers = serde_json::Map::new();
    let mut fails = Vec::new();
    for (name, range) in parts {
        let (bad, first) = word_mismatches(&got.records, &want, range, name);
        numbers.insert(format!("{name}_word_mismatches"), json!(bad));
        if bad > 0 {
            fails.push(format!("{name}: {bad} words differ ({})", first.join(", ")));
        }
    }
    let tiles: Vec<(u32, u32)> =
        (0..launched as u32).map(|g| (g % shape[0], g / shape[0] % shape[1] + shape[1] * (g / (shape[0] * shape[1])))).collect();
    let (bad, first) = image_mismatches(&got.image.stencil, &tiles_image(size, &tiles), size.0);
    numbers.insert("stencil_mismatches".into(), json!(bad));
    if let Some(f) = first {
        fails.push(format!("stencil: {bad} of {} pixels differ (first {f})", size.0 * size.1));
    }
    numbers.insert("header_7x3x2".into(), json!(&got.records[a..a + HEADER]));
    numbers.insert("header_65535".into(), json!(&got.records[big..big + HEADER]));
    numbers.insert("seconds".into(), json!(seconds));
    let what = "vkCmdDrawMeshTasksEXT (7, 3, 2): every workgroup once with its workgroup_id, num_workgroups and 4 local \
                indices, its tile counted once; (0, 1, 1) and (2, 0, 1) launch nothing; (65535, 1, 1), the most one draw of \
                --method mesh launches: every workgroup once";
    Ok(CheckResult::from_fails("group_counts", fails, numbers, what))
}

/// What task workgroup `j` of `spawn` launches: (j % 4, 1 + j % 3, 1).
fn launch_of(j: u32) -> [u32; 3] {
    [j % 4, 1 + j % 3, 1]
}

/// `mesh.task_payload`.
pub fn task_payload(ctx: &Context) -> Result<CheckResult> {
    let format = ctx.depth_format;
    let shape = [4u32, 3, 1];
    let tasks = shape[0] * shape[1];
    let size = (shape[0] * 3 * TILE, shape[1] * 3 * TILE);
    let total = tasks as usize * (1 + SPAWN_SLOTS * 4);
    let mut rig = Rig::new(ctx, &[], &[], total)?;
    let both = PipeState::stencil(vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::INCREMENT_AND_WRAP);
    let pipeline = rig.pipeline(Some(c"spawn"), c"spawned", format, both)?;
    let push = Push::new(pixels(size.0, size.1), [0.0; 4], 0, (0, tasks, 0));
    let got = rig.render(format, size, (0.0, 0), &[Draw { pipeline, push, groups: shape, ops: None }])?;
    let mut want = vec![0u32; total];
    let mut tiles = Vec::new();
    let mut mesh_groups = 0;
    for j in 0..tasks {
        want[j as usize] = SPAWN_WG;
        let [nx, ny, _] = launch_of(j);
        for s in 0..nx * ny {
            let at = tasks as usize + (j as usize * SPAWN_SLOTS + s as usize) * 4;
            want[at..at + 4].copy_from_slice(&[GROUP_WG, j + 1, pack(nx, ny, 1), 0]);
            tiles.push(((j % 4) * 3 + s % nx, (j / 4) * 3 + s / nx));
            mesh_groups += 1;
        }
    }
    // The test seam (`value_images::skewed`): one invocation more in the first task workgroup.
    want[0] += u32::from(crate::value_images::skewed());
    let mut numbers = serde_json::Map::new();
    let mut fails = Vec::new();
    for (name, range) in [("task_invocations", 0..tasks as usize), ("mesh_slots", tasks as usize..total)] {
        let (bad, first) = word_mismatches(&got.records, &want, range, name);
        numbers.insert(format!("{name}_word_mismatches"), json!(bad));
        if bad > 0 {
            fails.push(format!("{name}: {bad} words differ ({})", first.join(", ")));
        }
    }
    let (bad, first) = image_mismatches(&got.image.stencil, &tiles_image(size, &tiles), size.0);
    numbers.insert("stencil_mismatches".into(), json!(bad));
    if let Some(f) = first {
        fails.push(format!("stencil: {bad} of {} pixels differ (first {f})", size.0 * size.1));
    }
    let payload_bad: u32 = (0..tasks as usize * SPAWN_SLOTS).map(|s| got.records[tasks as usize + 4 * s + 3]).sum();
    numbers.insert("payload_words_differing".into(), json!(payload_bad));
    numbers.insert("task_workgroups".into(), json!(tasks));
    numbers.insert("mesh_workgroups".into(), json!(mesh_groups));
    let what = format!(
        "{tasks} task workgroups ((4, 3, 1)) launching (j % 4, 1 + j % 3, 1) mesh workgroups each ({mesh_groups} in all, 0 to 9 \
         a task): each once, with the payload every task invocation wrote and its own num_workgroups; its tile counted once"
    );
    Ok(CheckResult::from_fails("task_payload", fails, numbers, &what))
}
