//! Conformance coverage of what umbrage records: every Vulkan command, dynamic state, image
//! layout, load/store op, query type and flag, and depth/stencil pipeline state that the
//! renderer, `ShadowPass`, the viewer, the bench and the example hosts (`src/` and `crates/` but the suite
//! itself, and `examples/`) record must have a row in `COVERAGE` naming the `umbrage conform`
//! family that checks its spec semantics — or saying why none can. The rows' families must name
//! real cases. The table, with where each item is recorded, is `docs/conform/coverage.md`:
//! this test regenerates it and fails when the committed one differs (the new one is written:
//! commit it).
//!
//! No device: runs everywhere.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// How a row is covered.
#[derive(Clone, Copy, PartialEq, Eq)]
enum How {
    /// A family checks the item's own semantics against the CPU model.
    Exact,
    /// Only through what it serves: the end-to-end renders against the exact reference.
    EndToEnd,
    /// Nothing to compare (the spec leaves the result undefined) or no family yet: the reason
    /// says which.
    Gap,
}

struct Row {
    /// The scanned item (`vkCmdClearAttachments`, `VK_IMAGE_LAYOUT_UNDEFINED`,
    /// `depthClampEnable`).
    item: &'static str,
    /// Case-name globs of the families that cover it (none for a gap).
    families: &'static [&'static str],
    how: How,
    /// What the families check of it, or why nothing does.
    what: &'static str,
}

const fn exact(item: &'static str, families: &'static [&'static str], what: &'static str) -> Row {
    Row { item, families, how: How::Exact, what }
}
const fn end_to_end(item: &'static str, families: &'static [&'static str], what: &'static str) -> Row {
    Row { item, families, how: How::EndToEnd, what }
}
const fn gap(item: &'static str, what: &'static str) -> Row {
    Row { item, families: &[], how: How::Gap, what }
}

const EVERY_DRAW: &[&str] = &["stencil.*", "depth.*", "raster.*", "wrap.*", "clip.*", "watertight.*", "occlusion.*"];

/// The table. Sorted as it is printed: by kind, then by name.
const COVERAGE: &[Row] = &[
    // Commands.
    exact("vkCmdBeginQuery", &["commands.queries", "occlusion.*", "raster.*.occlusion.*"], "occlusion (precise) and pipeline-statistics queries begun inside a rendering instance; counts exact"),
    exact("vkCmdBeginRenderPass", &["*.render_pass.*", "commands.clears"], "every family in a classic render pass; load ops per aspect within a partial render area, clear values"),
    exact("vkCmdBeginRendering", &["*.dynamic_rendering.*", "commands.clears"], "every family in dynamic rendering; separate depth and stencil load ops on one view within a partial render area"),
    end_to_end("vkCmdBindDescriptorSets", &["pipeline.hard_cases.*"], "the renderer's lighting passes read the stencil and G-buffer through descriptor sets; the suite's own draws bind none"),
    exact("vkCmdBindIndexBuffer", &["legacy.index_types", "commands.indirect"], "u8, u16 and u32 index buffers give identical stencil images; indirect draws through a u16 buffer"),
    exact("vkCmdBindPipeline", EVERY_DRAW, "every case binds the pipeline of its state (static state) or one with deliberately wrong static state (dynamic state)"),
    exact("vkCmdBindVertexBuffers", EVERY_DRAW, "every case's vertices"),
    exact("vkCmdBlitImage", &["commands.blit_copy_color"], "NEAREST, 7x5 -> 16x9, RGBA8 -> RGBA8 and BGRA8: every texel"),
    gap("vkCmdBuildAccelerationStructures", "ray query only (`--method rayquery`): held to the exact reference by tests/engine/hard_cases.rs and tests/engine/rayquery.rs on lavapipe 25.0.7; the suite's pipeline cases do not run ray query"),
    exact("vkCmdClearAttachments", &["commands.clears"], "per aspect mask (stencil, depth, both) with several rects, inside a rendering instance and a subpass; only the low 8 stencil bits; scissor ignored"),
    gap("vkCmdCopyAccelerationStructure", "ray query compaction: as vkCmdBuildAccelerationStructures"),
    exact("vkCmdCopyBuffer", &["commands.buffers"], "two regions at offsets within one buffer: every byte"),
    exact("vkCmdCopyImage", &["commands.blit_copy_color"], "RGBA8 to RGBA8: every byte"),
    exact("vkCmdCopyImageToBuffer", &["commands.copy_aspects", "commands.blit_copy_color", "*"], "depth (2 bytes D16, 4 bytes X8D24/D32) and stencil (1 byte) aspects at buffer offsets with row length and image height beyond the region, from an image offset; every case reads back through it"),
    exact("vkCmdDispatch", &["commands.dispatch", "commands.dispatch_indirect"], "2D group counts (65535, 2) as the compute silhouettes split a dispatch: every group and invocation once with workgroup_id, num_workgroups and local index; storage-buffer atomicAdd, atomicOr and atomicMax exact; ids past n skip; group counts of 0 dispatch nothing"),
    exact("vkCmdDispatchIndirect", &["commands.dispatch_indirect"], "a command at byte offset 20 of a host-visible storage buffer, grown by an earlier dispatch's atomicMax (compute write -> indirect read barrier): exactly its groups, each once with its workgroup_id and num_workgroups; x = 0 dispatches nothing"),
    exact("vkCmdDraw", EVERY_DRAW, "every non-indexed case"),
    exact("vkCmdDrawIndexed", &["legacy.index_types", "watertight.*"], "indexed meshes, split across draws"),
    exact("vkCmdDrawIndexedIndirect", &["commands.indirect", "commands.multi_draw_indirect"], "one record per call at non-zero offsets (stride 20), firstIndex, vertexOffset, instanceCount 0 and 2; multi-draw (drawCount 4 and 2, stride 20) with per-record vertexOffset, firstIndex and firstInstance (per-instance attributes, shadow.vert's TABLE variant), as the compute path's merged draws"),
    exact("vkCmdDrawIndexedIndirectCount", &["commands.draw_indirect_count"], "the count read from a buffer written earlier in the submission (transfer -> indirect barrier): min(count, maxDrawCount) records drawn (count below, above and 0), each record's vertexOffset, firstIndex and firstInstance exact, as the compute path's merged draws; unsupported without drawIndirectCount (Vulkan 1.2)"),
    exact("vkCmdDrawMeshTasks", &["mesh.*"], "VK_EXT_mesh_shader (skipped as unsupported without it; passes on lavapipe 25.0.7): group counts (7, 3, 2), (65535, 1, 1), 0 in x or y; task workgroups launching 0 to 9 mesh workgroups with their payload; w = 0 and near-zero-w vertices with and without depth clamp; a closed volume from 24 meshlets: every pixel and recorded word exact"),
    exact("vkCmdEndQuery", &["commands.queries", "occlusion.*"], "as vkCmdBeginQuery"),
    exact("vkCmdEndRenderPass", &["*.render_pass.*", "commands.clears"], "store ops of both aspects"),
    exact("vkCmdEndRendering", &["*.dynamic_rendering.*", "commands.clears"], "store ops of both aspects"),
    exact("vkCmdFillBuffer", &["commands.fill_buffer", "commands.dispatch", "commands.dispatch_indirect"], "sub-ranges at offsets, over an earlier fill, VK_WHOLE_SIZE to the last whole word: every byte; zeroes the words compute atomics then accumulate"),
    gap("vkCmdNextSubpass", "examples/embed's render-pass host only (its second subpass): tests/engine/embed.rs compares its stencil with the dynamic-rendering host's; the suite's render passes have one subpass"),
    exact("vkCmdPipelineBarrier", &["commands.layouts", "*"], "Vulkan 1.0-1.2 devices' barriers: layout transitions keep contents"),
    exact("vkCmdPipelineBarrier2", &["commands.layouts", "*"], "layout transitions keep both aspects' contents through every layout umbrage uses"),
    exact("vkCmdPushConstants", EVERY_DRAW, "every case's transform through shadow.vert's push block"),
    exact("vkCmdResetQueryPool", &["commands.queries"], "a whole pool, then a sub-range again; a reset, never-begun query reads as unavailable"),
    exact("vkCmdSetDepthBounds", &["depth.*.bounds.*", "legacy.depth_bounds"], "inclusive bounds, min = max, ranges outside [0, 1] with VK_EXT_depth_range_unrestricted"),
    exact("vkCmdSetScissor", &["commands.scissor"], "per draw: inside, past the image's edge, empty"),
    exact("vkCmdSetViewport", &["depth.*.unrestricted.*", "*"], "viewport depth ranges [0, 4] and [-2, 1]; every case's pixel mapping"),
    exact("vkCmdUpdateBuffer", &["commands.buffers"], "64 bytes at an offset: every byte, nothing else written"),
    gap("vkCmdWriteAccelerationStructuresProperties", "ray query compaction: as vkCmdBuildAccelerationStructures"),
    exact("vkCmdWriteTimestamp", &["commands.queries"], "in order (Vulkan 1.0-1.2 devices)"),
    exact("vkCmdWriteTimestamp2", &["commands.queries"], "in order"),
    // Dynamic state.
    exact("VK_DYNAMIC_STATE_DEPTH_BOUNDS", &["depth.*.bounds.*"], "bounds set per draw, static and dynamic state models"),
    exact("VK_DYNAMIC_STATE_SCISSOR", &["commands.scissor"], "per draw"),
    exact("VK_DYNAMIC_STATE_VIEWPORT", &["depth.*.unrestricted.*", "*"], "per draw"),
    // Image layouts.
    exact("VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL", &["commands.blit_copy_color"], "an RGBA8 image's contents kept through it"),
    exact("VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_STENCIL_READ_ONLY_OPTIMAL", &["commands.layouts"], "both aspects kept through it (Vulkan 1.1)"),
    exact("VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL", &["*"], "every depth-stencil case draws in it"),
    exact("VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL", &["commands.layouts"], "both aspects kept through it"),
    gap("VK_IMAGE_LAYOUT_PRESENT_SRC_KHR", "swapchain images only (the viewer): tests/cli/view.rs under Xvfb checks the screenshots; the suite has no swapchain"),
    exact("VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL", &["commands.layouts", "commands.blit_copy_color"], "depth-stencil (where sampled) and colour contents kept through it"),
    exact("VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL", &["commands.layouts", "commands.blit_copy_color"], "blit and copy destinations; contents kept through it"),
    exact("VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL", &["*"], "every read-back"),
    gap("VK_IMAGE_LAYOUT_UNDEFINED", "the contents after a transition from it are undefined: nothing to compare (every case starts there, then clears)"),
    // Load and store ops.
    exact("VK_ATTACHMENT_LOAD_OP_CLEAR", &["commands.clears", "*"], "per aspect, only within the render area"),
    gap("VK_ATTACHMENT_LOAD_OP_DONT_CARE", "contents undefined by the spec: nothing to compare"),
    exact("VK_ATTACHMENT_LOAD_OP_LOAD", &["commands.clears"], "per aspect: kept inside and outside the render area"),
    exact("VK_ATTACHMENT_STORE_OP_STORE", &["commands.clears", "*"], "both aspects stored"),
    // Queries.
    exact("VK_QUERY_CONTROL_PRECISE_BIT", &["commands.queries", "occlusion.*", "raster.*.occlusion.*"], "exact sample counts (where occlusionQueryPrecise)"),
    exact("VK_QUERY_PIPELINE_STATISTIC_CLIPPING_PRIMITIVES_BIT", &["commands.queries"], "in flag-bit order; 3 to 5 of 5 triangles, two outside the view"),
    exact("VK_QUERY_PIPELINE_STATISTIC_INPUT_ASSEMBLY_PRIMITIVES_BIT", &["commands.queries"], "in flag-bit order; exactly 5"),
    exact("VK_QUERY_PIPELINE_STATISTIC_VERTEX_SHADER_INVOCATIONS_BIT", &["commands.queries"], "in flag-bit order; at least the visible triangles' 9 vertices"),
    exact("VK_QUERY_RESULT_64_BIT", &["commands.queries"], "64- and 32-bit reads agree, from a first query"),
    exact("VK_QUERY_RESULT_WAIT_BIT", &["commands.queries"], "results of ended queries"),
    gap("VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR", "ray query compaction: as vkCmdBuildAccelerationStructures"),
    exact("VK_QUERY_TYPE_OCCLUSION", &["commands.queries", "occlusion.*"], "counts exact per query"),
    exact("VK_QUERY_TYPE_PIPELINE_STATISTICS", &["commands.queries"], "the three statistics umbrage reads"),
    exact("VK_QUERY_TYPE_TIMESTAMP", &["commands.queries"], "in order"),
    // Depth, stencil and rasterisation state.
    exact("VK_COMPARE_OP_*", &["stencil.*.compare.*", "depth.*"], "every compare op, stencil and depth"),
    exact("VK_CULL_MODE_*", &["stencil.*.two_sided.*", "pipeline.hard_cases.*"], "NONE in every two-sided case; FRONT/BACK (shadow maps, one-sided passes) end to end"),
    exact("VK_FILTER_NEAREST", &["commands.blit_copy_color"], "the blit's filter"),
    exact("VK_INDEX_TYPE_*", &["legacy.index_types"], "u8 (VK_EXT_index_type_uint8), u16, u32"),
    exact("VK_STENCIL_OP_*", &["stencil.*.ops.*", "wrap.*"], "every op pair per face"),
    exact("depthBiasEnable", &["depth.*.clamp.*"], "constant bias ±2e8 with clamp: every fragment at exactly 1.0 / 0.0"),
    exact("depthBoundsTestEnable", &["depth.*.bounds.*", "legacy.depth_bounds"], "stored depth against inclusive bounds"),
    exact("depthClampEnable", &["depth.*.clamp.*", "clip.*"], "on and off, near and far planes, w <= 0"),
    exact("stencilTestEnable", &["stencil.*"], "every stencil case; dynamic on/off in the dynamic state model"),
];

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

fn ident_at(s: &str, i: usize, upper: bool) -> &str {
    let rest = &s[i..];
    let end = rest
        .find(|c: char| !(c.is_ascii_digit() || c == '_' || if upper { c.is_ascii_uppercase() } else { c.is_ascii_lowercase() }))
        .unwrap_or(rest.len());
    &rest[..end]
}

fn camel(snake: &str) -> String {
    snake.split('_').map(|w| w[..1].to_uppercase() + &w[1..]).collect()
}

/// `vk::<Enum>::` prefixes scanned, and the item each value becomes (`None`: one row for the
/// whole enum, named with `_*`).
const ENUMS: &[(&str, &str, bool)] = &[
    ("DynamicState", "VK_DYNAMIC_STATE_", true),
    ("ImageLayout", "VK_IMAGE_LAYOUT_", true),
    ("AttachmentLoadOp", "VK_ATTACHMENT_LOAD_OP_", true),
    ("AttachmentStoreOp", "VK_ATTACHMENT_STORE_OP_", true),
    ("QueryType", "VK_QUERY_TYPE_", true),
    ("QueryResultFlags", "VK_QUERY_RESULT_", true),
    ("QueryControlFlags", "VK_QUERY_CONTROL_", true),
    ("QueryPipelineStatisticFlags", "VK_QUERY_PIPELINE_STATISTIC_", true),
    ("Filter", "VK_FILTER_", true),
    ("CompareOp", "VK_COMPARE_OP_", false),
    ("StencilOp", "VK_STENCIL_OP_", false),
    ("CullModeFlags", "VK_CULL_MODE_", false),
    ("IndexType", "VK_INDEX_TYPE_", false),
];

/// Pipeline-state builder calls scanned, and their Vulkan member names.
const STATES: &[(&str, &str)] = &[
    ("depth_clamp_enable", "depthClampEnable"),
    ("depth_bounds_test_enable", "depthBoundsTestEnable"),
    ("depth_bias_enable", "depthBiasEnable"),
    ("stencil_test_enable", "stencilTestEnable"),
];

/// The Vulkan name of a `vk::` value as the spec spells it (`_BIT` on flag bits, `64` as
/// `64_BIT`).
fn enum_item(prefix: &str, flags: bool, value: &str) -> String {
    if value == "TYPE_64" {
        return format!("{prefix}64_BIT");
    }
    if flags && !value.ends_with("_KHR") {
        return format!("{prefix}{value}_BIT");
    }
    format!("{prefix}{value}")
}

/// item -> files that record it.
fn scan(root: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files);
    rust_files(&root.join("crates"), &mut files);
    rust_files(&root.join("examples"), &mut files);
    let conform = root.join("crates/umbrage-conform");
    // umbrage's own `cmd_*` functions (methods that record several commands).
    let mut own = BTreeSet::new();
    for f in &files {
        let s = std::fs::read_to_string(f).unwrap();
        for (i, _) in s.match_indices("fn cmd_") {
            own.insert(ident_at(&s, i + 3, false).to_string());
        }
    }
    let mut found: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in files.iter().filter(|f| !f.starts_with(&conform)) {
        let s = std::fs::read_to_string(f).unwrap();
        let rel = f.strip_prefix(root).unwrap().to_string_lossy().into_owned();
        let mut add = |item: String| {
            found.entry(item).or_default().insert(rel.clone());
        };
        // `<receiver>.cmd_x(`: a Vulkan command when the receiver is an ash device or an
        // extension's function table (`d`, `device`, `ctx.device`, `device()`, a host's `raw` device, `l.fns`), not
        // one of umbrage's own `cmd_*` methods (`pass.cmd_determine`, `self.cmd_light_state`).
        for (i, _) in s.match_indices(".cmd_") {
            let name = ident_at(&s, i + 1, false);
            if !s[i + 1 + name.len()..].trim_start().starts_with('(') {
                continue;
            }
            let receiver = s[..i].trim_end().trim_end_matches("()");
            let last = receiver.rsplit(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).next().unwrap_or("");
            if ["d", "device", "raw", "fns", "loader"].contains(&last) {
                add(format!("vk{}", camel(name)));
            } else {
                assert!(
                    own.contains(name),
                    "{rel}: `{last}.{name}(` is neither an ash call (receiver d, device, raw, fns or loader) nor one of umbrage's own `fn {name}`: teach the scan its receiver"
                );
            }
        }
        for &(ty, prefix, per_value) in ENUMS {
            let pat = format!("vk::{ty}::");
            for (i, _) in s.match_indices(&pat) {
                let value = ident_at(&s, i + pat.len(), true);
                if value.is_empty() || value == "from_raw" {
                    continue;
                }
                let flags = ty.ends_with("Flags") || ty == "QueryPipelineStatisticFlags";
                add(if per_value { enum_item(prefix, flags, value) } else { format!("{prefix}*") });
            }
        }
        for &(call, item) in STATES {
            if s.contains(&format!(".{call}(")) {
                add(item.to_string());
            }
        }
    }
    found
}

fn how_name(h: How) -> &'static str {
    match h {
        How::Exact => "exact",
        How::EndToEnd => "end to end",
        How::Gap => "**gap**",
    }
}

fn render(found: &BTreeMap<String, BTreeSet<String>>) -> String {
    let mut s = String::from(
        "# What umbrage records, and the conformance family that checks it\n\n\
         Generated by `cargo test --test engine conform_coverage::` from the code: every Vulkan command, dynamic state, image layout, \
         load/store op, query type and flag, and depth/stencil/rasterisation state that `src/` and `crates/` (but the suite itself, \
         `crates/umbrage-conform/`) and the example hosts (`examples/`) record, with the `umbrage conform` family that checks its spec \
         semantics against the CPU model. *exact*: a family checks the item itself; *end to end*: only through the whole \
         shadow pipeline against the exact reference; **gap**: nothing to compare, or no family yet (the reason says which). \
         The test fails when something is recorded that this table lacks, or when a family names no case.\n\n\
         The `commands.*` family (`crates/umbrage-conform/src/checks/commands.rs`) was added for this table: clears and load ops per aspect, \
         aspect copies with offsets and strides, layout transitions, blits and copies, buffer updates and copies, queries, \
         scissors and indirect draws; buffer fills, dispatches and indirect dispatches.\n\n\
         | item | covered | families | what is checked | recorded in |\n|---|---|---|---|---|\n",
    );
    let (mut exact, mut e2e, mut gaps) = (0, 0, 0);
    for r in COVERAGE {
        let Some(files) = found.get(r.item) else { continue };
        match r.how {
            How::Exact => exact += 1,
            How::EndToEnd => e2e += 1,
            How::Gap => gaps += 1,
        }
        let fams: Vec<String> = r.families.iter().map(|f| format!("`{f}`")).collect();
        let files: Vec<String> = files.iter().map(|f| format!("`{f}`")).collect();
        s.push_str(&format!(
            "| `{}` | {} | {} | {} | {} |\n",
            r.item,
            how_name(r.how),
            if fams.is_empty() { "—".to_string() } else { fams.join(", ") },
            r.what,
            files.join(", ")
        ));
    }
    s.push_str(&format!("\n{} items: {exact} exact, {e2e} end to end, {gaps} gaps.\n", exact + e2e + gaps));
    s
}

#[test]
fn every_recorded_command_has_a_covering_family() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let found = scan(root);
    // The scan must see what umbrage is known to record (a broken scanner finds nothing).
    for must in ["vkCmdClearAttachments", "vkCmdDraw", "vkCmdDrawIndexedIndirect", "VK_DYNAMIC_STATE_DEPTH_BOUNDS", "depthClampEnable"] {
        assert!(found.contains_key(must), "the scan missed {must}: the scanner is broken");
    }
    let rows: BTreeSet<&str> = COVERAGE.iter().map(|r| r.item).collect();
    assert_eq!(rows.len(), COVERAGE.len(), "an item has two rows");
    let missing: Vec<String> = found
        .iter()
        .filter(|(k, _)| !rows.contains(k.as_str()))
        .map(|(k, files)| format!("{k} (recorded in {})", files.iter().cloned().collect::<Vec<_>>().join(", ")))
        .collect();
    assert!(
        missing.is_empty(),
        "recorded but missing from docs/conform/coverage.md's table (add a row to COVERAGE in tests/engine/conform_coverage.rs, \
         with the family that checks it): {missing:?}"
    );
    let names = umbrage_conform::suite::all_names();
    for r in COVERAGE {
        assert_eq!(r.families.is_empty(), r.how == How::Gap, "{}: a gap names no family, a covered row at least one", r.item);
        for f in r.families {
            assert!(names.iter().any(|n| umbrage_conform::suite::matches(f, n)), "{}: family {f} matches no case", r.item);
        }
    }
    let doc = render(&found);
    let path = root.join("docs/conform/coverage.md");
    let old = std::fs::read_to_string(&path).unwrap_or_default();
    if old != doc {
        std::fs::write(&path, &doc).unwrap();
        panic!("docs/conform/coverage.md was stale and has been regenerated: commit it");
    }
}

#[test]
fn rows_not_recorded_anywhere_are_dropped() {
    // A row whose item the code no longer records is dead weight: remove it.
    let found = scan(Path::new(env!("CARGO_MANIFEST_DIR")));
    let stale: Vec<&str> = COVERAGE.iter().map(|r| r.item).filter(|i| !found.contains_key(*i)).collect();
    assert!(stale.is_empty(), "rows for items nothing records any more: {stale:?}");
}
