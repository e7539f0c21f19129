//! The report's section on the frame's other passes (issue #38, item 5): the lighting and
//! G-buffer passes of `default` and `bench/fill` against the limits measured in the same run
//! ([`super::pass_limits`]), and, where the lighting pass is not within 1.5x of its limit,
//! the measured reasons: the shading math (`illuminate.frag` through the limit's own state)
//! and one rendering instance per light (the sweep's first point: one draw an instance).

use super::report::SuiteReport;
use super::row::SuiteRow;
use std::fmt::Write as _;

/// How far from its limit a pass may run and still count as near it.
pub const WITHIN: f64 = 1.5;

/// The scenes whose passes the section sets against their limits.
pub const SCENES: [&str; 2] = ["default", "bench/fill"];

/// What the section says of one scene's lighting pass, every time in ms.
#[derive(Clone, Debug, PartialEq)]
pub struct LightingGap {
    /// The pass as measured (`gpu_illuminate_ms`).
    pub measured: f64,
    /// Its lit pixels at the lighting limit's peak.
    pub at_peak: f64,
    /// The same pixels drawn one full-screen draw an instance (the limit sweep's first point).
    pub one_draw: f64,
    /// The same with `illuminate.frag`'s shading math (the shaded sweep's first point).
    pub shaded: f64,
}

impl LightingGap {
    /// The gap for `pixels` lit in `measured` ms at the run's lighting rates (Gpixels / s):
    /// `peak`, `one_draw` and `shaded_one_draw`; `None` where a rate is missing.
    pub fn of(pixels: u64, measured: f64, peak: f64, one_draw: f64, shaded_one_draw: f64) -> Option<LightingGap> {
        let at = |rate: f64| (rate > 0.0 && rate.is_finite()).then(|| pixels as f64 / (rate * 1e9) * 1e3);
        Some(LightingGap { measured, at_peak: at(peak)?, one_draw: at(one_draw)?, shaded: at(shaded_one_draw)? })
    }

    /// Measured over the time at the peak (1 = at the limit).
    pub fn ratio(&self) -> f64 {
        self.measured / self.at_peak
    }

    /// Whether the pass runs within [`WITHIN`] of its limit.
    pub fn within(&self) -> bool {
        self.ratio() <= WITHIN
    }

    /// The verdict in words: within the limit's 1.5x, or what the gap is made of: one
    /// rendering instance per light (the one-draw rate against the peak), the shading math
    /// (the shaded one-draw rate against the plain one), and what the pass costs beyond both.
    pub fn why(&self) -> String {
        if self.within() {
            return format!("within {WITHIN}x of its limit ({:.2}x)", self.ratio());
        }
        let instance = (self.one_draw - self.at_peak).max(0.0);
        let shading = (self.shaded - self.one_draw).max(0.0);
        let explained = instance + shading;
        let head = format!(
            "not within {WITHIN}x of its limit ({:.2}x): drawn one light to a rendering instance, as the pass must, the limit's own state takes {:.2} ms for these pixels (+{instance:.2} ms over the peak), and with `illuminate.frag`'s shading math {:.2} ms (+{shading:.2} ms)",
            self.ratio(),
            self.one_draw,
            self.shaded
        );
        let rest = self.measured - self.shaded;
        if rest <= 0.0 {
            format!(
                "{head}; the pass takes {:.2} ms, {:.2}x that: the whole gap to the limit is one instance per light ({:.0} %) and the shading math ({:.0} %)",
                self.measured,
                self.measured / self.shaded,
                100.0 * instance / explained.max(1e-12),
                100.0 * shading / explained.max(1e-12)
            )
        } else {
            let gap = self.measured - self.at_peak;
            format!(
                "{head}; the pass takes {:.2} ms: of its {gap:.2} ms gap, one instance per light is {:.0} %, the shading math {:.0} %, and {rest:.2} ms ({:.0} %) is the pass's own beyond both",
                self.measured,
                100.0 * instance / gap,
                100.0 * shading / gap,
                100.0 * rest / gap
            )
        }
    }
}

impl SuiteReport {
    /// The row that times `scene`'s frame with McGuire and every optimisation on.
    fn frame_row(&self, scene: &str) -> Option<&SuiteRow> {
        let mcguire = |r: &&SuiteRow| r.scene == scene && r.method == "mcguire" && r.gpu_illuminate_ms.is_some();
        let rows: Vec<&SuiteRow> = self.rows.iter().filter(mcguire).collect();
        rows.iter().find(|r| r.sweep == "scenes").or_else(|| rows.iter().find(|r| r.variant == "all-on")).copied()
    }

    /// The lighting and G-buffer passes of [`SCENES`] against their limits, measured in this
    /// run.
    pub(super) fn frame_passes_markdown(&self) -> String {
        let l = &self.limits;
        let rows: Vec<&SuiteRow> = SCENES.iter().filter_map(|s| self.frame_row(s)).collect();
        if rows.is_empty() || l.lighting_gpix_s <= 0.0 {
            return String::new();
        }
        let mut s = String::from("## The frame's other passes against their limits\n\n");
        let _ = writeln!(
            s,
            "Measured in this run on a {}x{} target (`limits`): the lighting limit — full-screen draws reading the G-buffer and adding into the accumulation target under the stencil test, without the shading math — peaks at {:.3} Gpixels/s, {:.3} with one draw a rendering instance (as each light's pass is drawn); the real `illuminate.frag` through the same state reaches {:.3} (peak) and {:.3} (one draw an instance); an empty lighting instance costs {:.3} ms. The G-buffer pipeline reaches {:.2} Mtriangles/s on 2-pixel triangles and {:.3} Gpixels/s filling full-screen layers. The rows are McGuire's on each scene (all optimisations on), their passes timed in the same frames as their shadows.\n",
            l.target[0],
            l.target[1],
            l.lighting_gpix_s,
            l.lighting_one_draw_gpix_s,
            l.lighting_shaded_gpix_s,
            l.lighting_shaded_one_draw_gpix_s,
            l.lighting_instance_ms,
            l.gbuffer_tri_mtri_s,
            l.gbuffer_fill_gpix_s,
        );
        let _ = writeln!(
            s,
            "| scene | size | lights | lit Mpixels | lighting ms | at the peak ms | one draw an instance ms | shaded, one draw ms | of the limit | G-buffer ms | triangles | of its triangle limit | of its fill limit |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|"
        );
        let mut verdicts = Vec::new();
        for r in &rows {
            let gap = r.gpu_illuminate_ms.and_then(|ms| {
                LightingGap::of(r.lit_pixels, ms, l.lighting_gpix_s, l.lighting_one_draw_gpix_s, l.lighting_shaded_one_draw_gpix_s)
            });
            let fill = r
                .gpu_depth_ms
                .filter(|ms| *ms > 0.0 && l.gbuffer_fill_gpix_s > 0.0)
                .map(|ms| r.width as f64 * r.height as f64 / (l.gbuffer_fill_gpix_s * 1e9) * 1e3 / ms);
            let pct = |v: Option<f64>| v.map_or("—".to_string(), |x| format!("{:.0} %", x * 100.0));
            let ms = |v: Option<f64>| v.map_or("—".to_string(), |x| format!("{x:.2}"));
            let _ = writeln!(
                s,
                "| {} | {}x{} | {} | {:.2} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                r.scene,
                r.width,
                r.height,
                r.lights,
                r.lit_pixels as f64 / 1e6,
                ms(r.gpu_illuminate_ms),
                ms(gap.as_ref().map(|g| g.at_peak)),
                ms(gap.as_ref().map(|g| g.one_draw)),
                ms(gap.as_ref().map(|g| g.shaded)),
                pct(r.lighting_limit_fraction),
                ms(r.gpu_depth_ms),
                r.gbuffer_triangles,
                pct(r.gbuffer_limit_fraction),
                pct(fill),
            );
            if let Some(g) = gap {
                verdicts.push(format!("- `{}`: the lighting pass is {}.", r.scene, g.why()));
            }
        }
        let _ = writeln!(s, "\n{}\n", verdicts.join("\n"));
        let _ = writeln!(
            s,
            "Each light's illumination is a rendering instance of its own (its scissor and depth bounds, the stencil its determination left), so it cannot reach the peak of many draws in one instance; and it runs the Blinn-Phong shading the limit leaves out. docs/lighting-limits.md has the analysis and the passes' changes.\n"
        );
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gap_is_split_into_what_the_limits_measured() {
        // 1 Mpixel: 10 ms at the peak (0.1 Gpix/s), 15 ms one draw an instance, 20 ms shaded.
        let g = LightingGap::of(1_000_000, 21.0, 0.1, 1.0 / 15.0, 0.05).unwrap();
        assert!((g.at_peak - 10.0).abs() < 1e-9 && (g.one_draw - 15.0).abs() < 1e-9 && (g.shaded - 20.0).abs() < 1e-9);
        assert!(!g.within() && (g.ratio() - 2.1).abs() < 1e-12);
        let why = g.why();
        assert!(why.contains("not within 1.5x of its limit (2.10x)") && why.contains("takes 15.00 ms for these pixels (+5.00 ms"), "{why}");
        assert!(why.contains("one instance per light is 45 %, the shading math 45 %, and 1.00 ms (9 %)"), "{why}");
        // Faster than its own shader through the limit's state: the gap is all explained.
        let fast = LightingGap::of(1_000_000, 19.0, 0.1, 1.0 / 15.0, 0.05).unwrap().why();
        assert!(
            fast.contains("0.95x that: the whole gap to the limit is one instance per light (50 %) and the shading math (50 %)"),
            "{fast}"
        );
        let near = LightingGap::of(1_000_000, 14.0, 0.1, 0.1, 0.1).unwrap();
        assert!(near.within() && near.why().starts_with("within 1.5x"));
        assert!(LightingGap::of(1, 1.0, 0.0, 1.0, 1.0).is_none());
    }
}
