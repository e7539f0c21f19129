//! `ShadowPass::prepare`: one frame's CPU work (culling, cases, silhouettes, index streams,
//! the plans kept across frames) into a ring slot.

use super::*;

impl ShadowPass {
    /// The CPU work of one frame into ring slot `slot`: per light culling, cases, possible
    /// silhouettes and index streams. The host guarantees that the frame that last used
    /// `slot` has retired (its buffers are rewritten and its retired buffers freed).
    ///
    /// ```no_run
    /// # use umbrage::pass::*; use glam::{DVec3, Mat4, Vec3};
    /// # use umbrage::geom::Light;
    /// # fn f(pass: &mut ShadowPass, frame_number: usize, camera_view: Mat4, proj: Mat4) -> umbrage::Result<()> {
    /// let eye = DVec3::new(0.0, 4.0, 7.0);
    /// let view = ShadowView::from_view_matrix(eye, camera_view, proj, (1280, 720))?;
    /// let light = Light::point(Vec3::new(2.0, 6.0, 2.0));
    /// // Slot `frame_number % 2`: the host waited for that slot's previous frame first.
    /// let frame = pass.prepare(frame_number % 2, &view, &[light])?;
    /// for l in &frame.lights {
    ///     println!("scissor {:?}, {} casters planned", l.scissor, l.stats.casters.len());
    /// }
    /// # Ok(()) }
    /// ```
    pub fn prepare(&mut self, slot: usize, view: &ShadowView, lights: &[Light]) -> Result<PreparedFrame> {
        self.prepare_with(slot, view, lights, true)
    }

    /// As [`prepare`](Self::prepare), with every caster culled: only the lights' scissors and
    /// depth bounds (and pending uploads; no ray-query structures, whatever the technique). For hosts that determine this frame's shadows
    /// another way (umbrage's shadow-map baseline) but keep the pass's per-light state.
    pub fn prepare_culled(&mut self, slot: usize, view: &ShadowView, lights: &[Light]) -> Result<PreparedFrame> {
        self.prepare_with(slot, view, lights, false)
    }

    fn prepare_with(&mut self, slot: usize, view: &ShadowView, lights: &[Light], casters: bool) -> Result<PreparedFrame> {
        if slot >= self.slots.len() {
            return Err(Misuse::SlotOutOfRange { slot, slots: self.slots.len() }.into());
        }
        view.check()?;
        check_lights(lights)?;
        if casters {
            spheres::check(&self.spheres, lights)?;
        }
        self.settings.check(&self.caps)?;
        // A culled frame prepares no rays either, whatever the technique (a shadow-map frame
        // after a ray-query one must not build a top level nobody traces).
        let rays = casters && self.settings.technique == Technique::RayQuery;
        let casters = casters && !rays;
        if rays {
            self.check_rays()?;
        }
        if self.casters.cpu.iter().any(|c| c.transmittance.is_some()) && self.pipes.transmit.is_none() {
            return Err(
                Misuse::NotConfigured { call: "prepare (with transparent casters)", needs: "ShadowPassDesc::transmit_format" }.into()
            );
        }
        // The slot's previous frame has retired: free its staging copies and what waited for it.
        for mut b in self.slots[slot].staging.drain(..) {
            b.destroy(&self.dev);
        }
        self.casters.slot_retired(&self.dev, slot);
        self.kept.slot_retired(&self.dev, slot);
        self.techniques.slot_retired(&self.dev, slot);
        if self.settings.technique == Technique::EdgeQuads {
            self.casters.ensure_edge_quads(&self.dev)?;
        }
        if matches!(self.settings.technique, Technique::Compute | Technique::Mesh) {
            self.create_pipelines(self.settings.technique)?;
            let all = self.all_slots();
            self.casters.ensure_compute(&self.dev, all)?;
        }
        // What the slot's previous frame recorded has reached the GPU; everything else still
        // pending rides with this frame (a dropped or abandoned frame loses nothing).
        let recorded = std::mem::take(&mut self.slots[slot].recorded);
        let (uploads, upload_bytes) = self.casters.carry_uploads(slot, recorded.load(Ordering::Acquire));
        let uploads_recorded = self.slots[slot].recorded.clone();

        let (kept, keep_stats) = self.plan_kept(view, lights, casters)?;
        let packed = pack(
            &self.casters,
            &PackInput {
                view,
                direction: self.desc.depth_direction,
                lights,
                settings: self.settings,
                u8_ok: self.caps.index_type_uint8,
                depth_bounds: self.caps.depth_bounds && self.settings.toggles.depth_bounds,
                casters,
                planar_receiver: self.techniques.planar.receiver,
                spheres: &self.spheres,
            },
            kept,
        );
        let record_start = Instant::now();
        let stream = self.write_stream(slot, &packed.stream)?;
        // The compute pass's records and descriptor sets count as recording work too.
        let compute = match packed.compute {
            Some(cf) => {
                // (mesh frames draw with mesh tasks: no indirect records to merge)
                let draws = match self.settings.technique {
                    Technique::Compute => self.caps.compute_draws(self.settings.toggles.compute_draws)?,
                    _ => ComputeDraws::PerChunk,
                };
                Some(self.prepare_compute(slot, cf, (lights.len(), draws))?)
            }
            None => None,
        };
        let ray_frame = match rays {
            true => {
                let scissors: Vec<vk::Rect2D> = packed.lights.iter().map(|l| l.scissor).collect();
                Some(self.prepare_rays(slot, view, lights, &scissors)?)
            }
            false => None,
        };
        let mut cpu = packed.cpu;
        cpu.record = record_start.elapsed().as_secs_f64() * 1e3;
        let mut totals = packed.totals;
        totals.bytes_sent += upload_bytes;
        totals.pairs_total =
            packed.lights.iter().map(|l| l.plan.casters.iter().filter(|c| c.case != crate::shadow::Case::Culled).count() as u64).sum();
        totals.pairs_replanned = totals.pairs_total;
        totals.kept_bytes = self.kept.bytes();
        if let Some(k) = keep_stats {
            if k.active {
                totals.pairs_kept = k.pairs_kept;
                totals.pairs_replanned = k.pairs_replanned;
                cpu.cull = k.cull_ms;
                cpu.plan += k.plan_ms;
            }
            totals.kept_evictions = k.evictions;
            totals.bytes_sent += k.bytes_written;
        }
        if let Some(cf) = &compute {
            totals.silhouette_read_bytes = 16 * (cf.exact_capacity + cf.sil_capacity);
            if let Some(m) = &cf.merged {
                totals.draws = totals.draws - m.per_chunk_calls + m.calls;
            }
        }
        let warnings = overflow_warnings(&self.casters, &packed.lights, self.settings.counter);
        let serial = self.serial;
        self.serial += 1;
        self.slots[slot].serial = Some(serial);
        Ok(PreparedFrame {
            pass: self.id,
            slot,
            serial,
            stream,
            uploads,
            uploads_recorded,
            lights: packed.lights,
            totals,
            cpu_ms: cpu,
            settings: self.settings,
            warnings,
            extent: vk::Extent2D { width: view.width, height: view.height },
            compute,
            rays: ray_frame,
        })
    }
}

impl ShadowPass {
    /// The frame's kept plans ([`PassSettings::keep`]) where the settings keep, with what the
    /// keeping did; `None` where the frame plans from scratch (a technique that plans on the
    /// GPU or not at all, `Method::ZPassClear`, keeping off, a zero budget, a culled frame).
    fn plan_kept(
        &mut self,
        view: &ShadowView,
        lights: &[Light],
        casters: bool,
    ) -> Result<(Option<Vec<keep::KeptLight>>, Option<keep::KeepStats>)> {
        let all_slots = self.all_slots();
        let method = match self.settings.technique {
            Technique::Volumes(m) if m != crate::shadow::Method::ZPassClear => Some(m),
            _ => None,
        };
        if !self.settings.keep || self.desc.keep_budget_bytes == 0 {
            let evicted = self.kept.clear(all_slots);
            return Ok((None, (evicted > 0).then(|| keep::KeepStats { evictions: evicted, ..Default::default() })));
        }
        let Some(method) = method.filter(|_| casters) else { return Ok((None, None)) };
        let fwd = view.forward(self.desc.depth_direction);
        let camera = crate::geom::Camera { eye: view.eye.as_vec3(), ..crate::geom::Camera::default() };
        let threads = match self.desc.plan_threads {
            0 => crate::geom::cpu::cores(),
            n => n,
        };
        let input = keep::KeepInput {
            camera: &camera,
            width: view.width,
            height: view.height,
            view_proj: fwd.world_view_proj(),
            lights,
            method,
            format: self.settings.index_format,
            u8_ok: self.caps.index_type_uint8,
            no_culling: !self.settings.toggles.culling,
            budget: self.desc.keep_budget_bytes,
            threads,
            all_slots,
        };
        let (l, s) = self.kept.plan_frame(&self.dev, &self.casters, &input)?;
        Ok((Some(l), Some(s)))
    }
}
