//! Recording GPU work: uploads, render passes (draws into targets), copies, readback.
//! The recorder inserts the barrier every texture needs between two uses, so an
//! algorithm only says what it reads and what it renders into.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::context::Device;
use super::error::{GpuError, Result};
use super::memory::{Buffer, Pod, as_bytes};
use super::pipeline::{BindingKind, Pipeline, Topology};

/// Vertices per segment when lavapipe splits a long triangle-list draw (see
/// [`RenderScope::draw`]).
pub const TRIANGLE_SEGMENT: u32 = 4095;
use super::texture::{TexFormat, Texture, Use};
use super::timer::Timestamps;

/// What happens to a target's old contents when a render pass starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Load {
    /// Keep them (accumulate: XOR, additive blending, several passes into one target).
    Keep,
    /// Clear to zero (0.0 or 0u: the same bits).
    Zero,
    /// Clear float targets to a value.
    Float([f32; 4]),
    /// Clear integer targets to a value.
    Uint([u32; 4]),
    /// Don't care: every texel that matters is written by the pass.
    Discard,
}

/// One colour attachment of a render pass: a texture layer and what to do with it first.
#[derive(Clone, Copy)]
pub struct Attachment<'a> {
    pub texture: &'a Texture,
    pub layer: u32,
    pub load: Load,
}

impl<'a> Attachment<'a> {
    pub fn new(texture: &'a Texture, load: Load) -> Attachment<'a> {
        Attachment { texture, layer: 0, load }
    }

    pub fn layer(texture: &'a Texture, layer: u32, load: Load) -> Attachment<'a> {
        Attachment { texture, layer, load }
    }

    /// One attachment per layer of `texture` (MRT over a layered target: layer l is
    /// colour attachment l, fragment output `location = l`).
    pub fn each_layer(texture: &'a Texture, load: Load) -> Vec<Attachment<'a>> {
        (0..texture.layers()).map(|l| Attachment::layer(texture, l, load)).collect()
    }
}

/// A texel rectangle: x, y, width, height.
pub type Rect = [u32; 4];

/// Records commands into one command buffer (see `Context::submit`).
pub struct Recorder<'d> {
    dev: &'d Arc<Device>,
    cmd: vk::CommandBuffer,
    /// Staging buffers that must live until the submission completes.
    keep: Vec<Buffer>,
}

impl<'d> Recorder<'d> {
    pub(crate) fn new(dev: &'d Arc<Device>, cmd: vk::CommandBuffer) -> Recorder<'d> {
        Recorder { dev, cmd, keep: Vec::new() }
    }

    /// The command buffer being recorded (for the swapchain's copy, in `present`).
    pub(crate) fn command_buffer(&self) -> vk::CommandBuffer {
        self.cmd
    }

    fn check(&self, tex: &Texture) -> Result<()> {
        if tex.same_device(&super::Context { dev: self.dev.clone() }) {
            Ok(())
        } else {
            Err(GpuError::Usage("a texture from another device was used".into()))
        }
    }

    fn check_copyable(&self, tex: &Texture) -> Result<()> {
        if tex.copyable() {
            Ok(())
        } else {
            Err(GpuError::Usage(format!(
                "a {}-sample {:?} target cannot be copied or sampled (resolve it first)",
                tex.samples(),
                tex.format()
            )))
        }
    }

    /// Makes `tex` ready for `next`: layout transition plus the memory dependency on its
    /// previous use. Read-after-read of the same kind needs nothing.
    pub(crate) fn use_texture(&mut self, tex: &Texture, next: Use) {
        let prev = tex.last_use.get();
        let needed = match prev {
            None => true,
            Some(p) => p != next || p.writes() || next.writes(),
        };
        if needed {
            let (old_layout, src_stage, src_access) = match prev {
                None => (vk::ImageLayout::UNDEFINED, vk::PipelineStageFlags2::NONE, vk::AccessFlags2::NONE),
                Some(p) => {
                    (p.layout(), p.stage(), if p.writes() { p.access() } else { vk::AccessFlags2::NONE })
                }
            };
            let barrier = [vk::ImageMemoryBarrier2::default()
                .src_stage_mask(src_stage)
                .src_access_mask(src_access)
                .dst_stage_mask(next.stage())
                .dst_access_mask(next.access())
                .old_layout(old_layout)
                .new_layout(next.layout())
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .image(tex.image)
                .subresource_range(
                    vk::ImageSubresourceRange::default()
                        .aspect_mask(tex.format().aspect())
                        .level_count(1)
                        .layer_count(vk::REMAINING_ARRAY_LAYERS),
                )];
            let dep = vk::DependencyInfo::default().image_memory_barriers(&barrier);
            // SAFETY: recording state; the image is alive for the whole submission.
            unsafe { self.dev.raw.cmd_pipeline_barrier2(self.cmd, &dep) };
        }
        tex.last_use.set(Some(next));
    }

    /// Test hook: records the next use of `tex` as already synchronized, so no barrier
    /// is emitted. Only for proving that validation catches the resulting hazard.
    #[doc(hidden)]
    pub fn skip_next_barrier_for_test(&mut self, tex: &Texture, as_sampled: bool) {
        tex.last_use.set(Some(if as_sampled { Use::Sampled } else { Use::CopySrc }));
    }

    /// Uploads `data` (tightly packed rows) into layer `layer` of `tex`.
    pub fn upload<T: Pod>(&mut self, tex: &Texture, layer: u32, data: &[T]) -> Result<()> {
        self.upload_region(tex, layer, [0, 0, tex.width(), tex.height()], data)
    }

    /// Uploads `data` (tightly packed rows of `rect`'s width) into the rectangle `rect` of
    /// layer `layer` of `tex`; the rest of the texture keeps its contents.
    pub fn upload_region<T: Pod>(&mut self, tex: &Texture, layer: u32, rect: Rect, data: &[T]) -> Result<()> {
        self.check(tex)?;
        self.check_copyable(tex)?;
        let bytes = as_bytes(data);
        let [x, y, w, h] = rect;
        let expected = w as u64 * h as u64 * tex.format().bytes_per_texel();
        if bytes.len() as u64 != expected
            || layer >= tex.layers()
            || w == 0
            || h == 0
            || x.checked_add(w).is_none_or(|e| e > tex.width())
            || y.checked_add(h).is_none_or(|e| e > tex.height())
        {
            return Err(GpuError::Usage(format!(
                "upload of {} bytes into layer {layer}, rect {rect:?} of a {}×{}×{} {:?} texture \
                 ({expected} bytes expected)",
                bytes.len(),
                tex.width(),
                tex.height(),
                tex.layers(),
                tex.format(),
            )));
        }
        let usage = vk::BufferUsageFlags::TRANSFER_SRC;
        let mut staging =
            Buffer::new(self.dev, bytes.len() as u64, usage, MemoryLocation::CpuToGpu, "upload")?;
        staging.write(0, bytes)?;
        self.use_texture(tex, Use::CopyDst);
        let region = [vk::BufferImageCopy::default()
            .image_subresource(
                vk::ImageSubresourceLayers::default()
                    .aspect_mask(vk::ImageAspectFlags::COLOR)
                    .base_array_layer(layer)
                    .layer_count(1),
            )
            .image_offset(vk::Offset3D { x: x as i32, y: y as i32, z: 0 })
            .image_extent(vk::Extent3D { width: w, height: h, depth: 1 })];
        // SAFETY: sizes checked above; buffer kept alive until the submission ends.
        unsafe {
            self.dev.raw.cmd_copy_buffer_to_image(
                self.cmd,
                staging.raw,
                tex.image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &region,
            )
        };
        self.keep.push(staging);
        Ok(())
    }

    /// Fills every layer of `tex` with zero.
    pub fn clear(&mut self, tex: &Texture) -> Result<()> {
        self.check(tex)?;
        self.check_copyable(tex)?;
        self.use_texture(tex, Use::CopyDst);
        let range = [vk::ImageSubresourceRange::default()
            .aspect_mask(vk::ImageAspectFlags::COLOR)
            .level_count(1)
            .layer_count(vk::REMAINING_ARRAY_LAYERS)];
        let value = vk::ClearColorValue { uint32: [0; 4] };
        // SAFETY: image in TRANSFER_DST layout (barrier above).
        unsafe {
            self.dev.raw.cmd_clear_color_image(
                self.cmd,
                tex.image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &value,
                &range,
            )
        };
        Ok(())
    }

    /// Copies all layers of `tex` to a new host-readable buffer (rows tightly packed,
    /// layer after layer). Read it after the submission with `Buffer::to_vec`.
    pub fn readback(&mut self, tex: &Texture) -> Result<Buffer> {
        self.readback_region(tex, 0..tex.layers(), [0, 0, tex.width(), tex.height()])
    }

    /// Copies a rectangle of some layers of `tex` to a new host-readable buffer.
    pub fn readback_region(
        &mut self,
        tex: &Texture,
        layers: std::ops::Range<u32>,
        rect: Rect,
    ) -> Result<Buffer> {
        let size = rect[2] as u64 * rect[3] as u64 * layers.len() as u64 * tex.format().bytes_per_texel();
        let buffer = Buffer::readback(self.dev, size)?;
        self.readback_into(tex, layers, rect, &buffer, 0)?;
        Ok(buffer)
    }

    /// Copies a rectangle of some layers of `tex` into `buffer` (made by
    /// `Buffer::readback`) at byte `offset`, rows tightly packed, layer after layer —
    /// many passes can share one readback buffer.
    pub fn readback_into(
        &mut self,
        tex: &Texture,
        layers: std::ops::Range<u32>,
        rect: Rect,
        buffer: &Buffer,
        offset: u64,
    ) -> Result<()> {
        self.check(tex)?;
        self.check_copyable(tex)?;
        let [x, y, w, h] = rect;
        let size = w as u64 * h as u64 * layers.len() as u64 * tex.format().bytes_per_texel();
        if layers.is_empty()
            || layers.end > tex.layers()
            || w == 0
            || h == 0
            || x.checked_add(w).is_none_or(|e| e > tex.width())
            || y.checked_add(h).is_none_or(|e| e > tex.height())
            || offset.checked_add(size).is_none_or(|e| e > buffer.size())
            || offset % 4 != 0
        {
            return Err(GpuError::Usage(format!(
                "readback of layers {layers:?}, rect {rect:?} from a {}×{}×{} texture into {} bytes at {offset} of a {}-byte buffer",
                tex.width(),
                tex.height(),
                tex.layers(),
                size,
                buffer.size()
            )));
        }
        self.use_texture(tex, Use::CopySrc);
        let region = [vk::BufferImageCopy::default()
            .buffer_offset(offset)
            .image_subresource(
                vk::ImageSubresourceLayers::default()
                    .aspect_mask(vk::ImageAspectFlags::COLOR)
                    .base_array_layer(layers.start)
                    .layer_count(layers.end - layers.start),
            )
            .image_offset(vk::Offset3D { x: x as i32, y: y as i32, z: 0 })
            .image_extent(vk::Extent3D { width: w, height: h, depth: 1 })];
        // Host reads of the buffer after the fence need the copy made visible to the host.
        let host = [vk::MemoryBarrier2::default()
            .src_stage_mask(vk::PipelineStageFlags2::COPY)
            .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags2::HOST)
            .dst_access_mask(vk::AccessFlags2::HOST_READ)];
        let dep = vk::DependencyInfo::default().memory_barriers(&host);
        // SAFETY: region checked above; the caller keeps the buffer at least until
        // `submit` returns.
        unsafe {
            self.dev.raw.cmd_copy_image_to_buffer(
                self.cmd,
                tex.image,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                buffer.raw,
                &region,
            );
            self.dev.raw.cmd_pipeline_barrier2(self.cmd, &dep);
        }
        Ok(())
    }

    /// Resets `timer` (call before the first `timestamp` of a submission).
    pub fn reset_timestamps(&mut self, timer: &Timestamps) {
        // SAFETY: the pool outlives the submission (borrowed by the caller).
        unsafe { self.dev.raw.cmd_reset_query_pool(self.cmd, timer.pool, 0, timer.capacity()) };
    }

    /// Writes GPU timestamp `index` once all previous commands have finished.
    pub fn timestamp(&mut self, timer: &Timestamps, index: u32) -> Result<()> {
        if index >= timer.capacity() {
            return Err(GpuError::Usage(format!("timestamp {index} of {}", timer.capacity())));
        }
        // SAFETY: index in range; pool reset earlier in this command buffer.
        unsafe {
            self.dev.raw.cmd_write_timestamp2(
                self.cmd,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                timer.pool,
                index,
            )
        };
        Ok(())
    }

    /// A render pass into `targets` over `area` (x, y, w, h; `None` = whole first target).
    /// Every texture a draw samples must be listed in `reads`, so its barrier is recorded
    /// before the pass begins.
    pub fn render<'p, T>(
        &mut self,
        targets: &[Attachment],
        area: Option<Rect>,
        reads: &'p [&'p Texture],
        draw: impl FnOnce(&mut RenderScope<'_, 'p>) -> Result<T>,
    ) -> Result<T> {
        self.render_into(Targets { colour: targets, resolve: &[], depth: None }, area, reads, draw)
    }

    /// A render pass with a depth buffer and/or multisampled colour targets resolved at its
    /// end (pictures of meshes); otherwise like [`Recorder::render`].
    pub fn render_into<'p, T>(
        &mut self,
        targets: Targets,
        area: Option<Rect>,
        reads: &'p [&'p Texture],
        draw: impl FnOnce(&mut RenderScope<'_, 'p>) -> Result<T>,
    ) -> Result<T> {
        let first = targets.colour.first().ok_or(GpuError::Internal("a render pass without a target"))?;
        let area = area.unwrap_or([0, 0, first.texture.width(), first.texture.height()]);
        let samples = first.texture.samples();
        self.check_targets(&targets, area, reads)?;
        for r in reads {
            self.check(r)?;
            self.use_texture(r, Use::Sampled);
        }
        let infos = self.colour_attachments(&targets)?;
        let depth_info = match &targets.depth {
            Some(d) => Some(self.depth_attachment(d)?),
            None => None,
        };
        let rect = vk::Rect2D {
            offset: vk::Offset2D { x: area[0] as i32, y: area[1] as i32 },
            extent: vk::Extent2D { width: area[2], height: area[3] },
        };
        let mut info =
            vk::RenderingInfo::default().render_area(rect).layer_count(1).color_attachments(&infos);
        if let Some(d) = &depth_info {
            info = info.depth_attachment(d);
        }
        // SAFETY: attachments transitioned above; they outlive the submission.
        unsafe { self.dev.raw.cmd_begin_rendering(self.cmd, &info) };
        let mut scope = RenderScope {
            dev: self.dev,
            cmd: self.cmd,
            area,
            targets: targets.colour,
            depth: targets.depth.map(|d| d.texture.format()),
            samples,
            reads,
            pipeline: None,
        };
        let result = draw(&mut scope);
        // SAFETY: matches the begin above, also when `draw` failed.
        unsafe { self.dev.raw.cmd_end_rendering(self.cmd) };
        result
    }

    /// Refuses targets a pass cannot render into: each must belong to this device, fit
    /// `area` and not be read in the pass; colour targets share one sample count, resolve
    /// targets match them one to one, the depth target has their sample count.
    fn check_targets(&self, targets: &Targets, area: Rect, reads: &[&Texture]) -> Result<()> {
        let samples = targets.colour.first().map_or(1, |a| a.texture.samples());
        let fits = |t: &Texture| {
            let [x, y, w, h] = area;
            if x + w > t.width() || y + h > t.height() || w == 0 || h == 0 {
                return Err(GpuError::Usage(format!(
                    "render area {area:?} does not fit a {}×{} target",
                    t.width(),
                    t.height()
                )));
            }
            if reads.iter().any(|r| std::ptr::eq(*r, t)) {
                return Err(GpuError::Usage("a texture cannot be read and rendered in the same pass".into()));
            }
            Ok(())
        };
        for a in targets.colour {
            self.check(a.texture)?;
            fits(a.texture)?;
            if a.texture.format().is_depth() || a.texture.samples() != samples {
                return Err(GpuError::Usage(format!(
                    "colour targets must be colour formats with one sample count ({:?} with {} samples)",
                    a.texture.format(),
                    a.texture.samples()
                )));
            }
        }
        if !targets.resolve.is_empty() {
            if targets.resolve.len() != targets.colour.len() || samples == 1 {
                return Err(GpuError::Usage(
                    "resolve targets need one per multisampled colour target".into(),
                ));
            }
            for (r, a) in targets.resolve.iter().zip(targets.colour) {
                self.check(r)?;
                fits(r)?;
                if !r.copyable() || r.format() != a.texture.format() {
                    return Err(GpuError::Usage(format!(
                        "cannot resolve {:?} into a {}-sample {:?} texture",
                        a.texture.format(),
                        r.samples(),
                        r.format()
                    )));
                }
            }
        }
        if let Some(d) = &targets.depth {
            self.check(d.texture)?;
            fits(d.texture)?;
            if !d.texture.format().is_depth() || d.texture.samples() != samples {
                return Err(GpuError::Usage(format!(
                    "the depth target is a {}-sample {:?} texture; a {samples}-sample depth format is needed",
                    d.texture.samples(),
                    d.texture.format()
                )));
            }
        }
        Ok(())
    }

    /// The colour attachments, each resolved into its resolve target if it has one.
    fn colour_attachments(&mut self, targets: &Targets) -> Result<Vec<vk::RenderingAttachmentInfo<'static>>> {
        let mut infos = Vec::with_capacity(targets.colour.len());
        for (i, a) in targets.colour.iter().enumerate() {
            self.use_texture(a.texture, Use::Attachment);
            let (op, clear) = load_op(a.load);
            let mut info = vk::RenderingAttachmentInfo::default()
                .image_view(a.texture.target_view(a.layer)?)
                .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                .load_op(op)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue { color: clear });
            if let Some(r) = targets.resolve.get(i) {
                self.use_texture(r, Use::Attachment);
                info = info
                    .resolve_mode(vk::ResolveModeFlags::AVERAGE)
                    .resolve_image_view(r.target_view(0)?)
                    .resolve_image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
            }
            infos.push(info);
        }
        Ok(infos)
    }

    /// The depth attachment (`Load::Float([d, ..])` clears it to d).
    fn depth_attachment(&mut self, d: &Attachment) -> Result<vk::RenderingAttachmentInfo<'static>> {
        self.use_texture(d.texture, Use::Depth);
        let (op, clear) = load_op(d.load);
        // SAFETY: every Load variant writes the first four bytes of the union.
        let value = unsafe { clear.float32[0] };
        Ok(vk::RenderingAttachmentInfo::default()
            .image_view(d.texture.target_view(0)?)
            .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
            .load_op(op)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue {
                depth_stencil: vk::ClearDepthStencilValue { depth: value, stencil: 0 },
            }))
    }
}

/// The load operation and clear value of `load`.
fn load_op(load: Load) -> (vk::AttachmentLoadOp, vk::ClearColorValue) {
    match load {
        Load::Keep => (vk::AttachmentLoadOp::LOAD, vk::ClearColorValue::default()),
        Load::Zero => (vk::AttachmentLoadOp::CLEAR, vk::ClearColorValue { uint32: [0; 4] }),
        Load::Float(v) => (vk::AttachmentLoadOp::CLEAR, vk::ClearColorValue { float32: v }),
        Load::Uint(v) => (vk::AttachmentLoadOp::CLEAR, vk::ClearColorValue { uint32: v }),
        Load::Discard => (vk::AttachmentLoadOp::DONT_CARE, vk::ClearColorValue::default()),
    }
}

/// The attachments of a render pass that draws pictures: colour targets, the
/// single-sample textures multisampled ones resolve into, and a depth buffer.
#[derive(Clone, Copy)]
pub struct Targets<'a> {
    pub colour: &'a [Attachment<'a>],
    /// One single-sample texture per colour target (multisampled targets only), or none.
    pub resolve: &'a [&'a Texture],
    /// A depth buffer (`Load::Float([d, ..])` clears it to d).
    pub depth: Option<Attachment<'a>>,
}

/// Inside a render pass: bind a pipeline and its inputs, then draw.
pub struct RenderScope<'r, 'p> {
    dev: &'r Arc<Device>,
    cmd: vk::CommandBuffer,
    area: Rect,
    targets: &'r [Attachment<'r>],
    depth: Option<TexFormat>,
    samples: u32,
    reads: &'p [&'p Texture],
    pipeline: Option<&'p Pipeline>,
}

impl<'p> RenderScope<'_, 'p> {
    /// Binds `pipeline` and sets the viewport to the pass's area.
    pub fn bind(&mut self, pipeline: &'p Pipeline) -> Result<()> {
        if !pipeline.targets.iter().copied().eq(self.targets.iter().map(|a| a.texture.format())) {
            let formats: Vec<TexFormat> = self.targets.iter().map(|a| a.texture.format()).collect();
            return Err(GpuError::Usage(format!(
                "pipeline {} renders {:?} but the pass targets are {formats:?}",
                pipeline.name, pipeline.targets
            )));
        }
        if pipeline.samples != self.samples || pipeline.depth != self.depth {
            return Err(GpuError::Usage(format!(
                "pipeline {} renders {} samples with depth {:?}, the pass {} samples with depth {:?}",
                pipeline.name, pipeline.samples, pipeline.depth, self.samples, self.depth
            )));
        }
        // SAFETY: recording inside a compatible dynamic-rendering pass.
        unsafe { self.dev.raw.cmd_bind_pipeline(self.cmd, vk::PipelineBindPoint::GRAPHICS, pipeline.raw) };
        self.pipeline = Some(pipeline);
        let [x, y, w, h] = self.area;
        self.viewport([x, y, w, h]);
        Ok(())
    }

    /// Restricts drawing to a rectangle inside the pass's area (the full-target quad then
    /// covers exactly this rectangle).
    pub fn viewport(&mut self, rect: Rect) {
        let [x, y, w, h] = rect;
        let vp = [vk::Viewport {
            x: x as f32,
            y: y as f32,
            width: w as f32,
            height: h as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        }];
        let sc = [vk::Rect2D {
            offset: vk::Offset2D { x: x as i32, y: y as i32 },
            extent: vk::Extent2D { width: w, height: h },
        }];
        // SAFETY: recording state; dynamic viewport/scissor are part of every texgeo pipeline.
        unsafe {
            self.dev.raw.cmd_set_viewport(self.cmd, 0, &vp);
            self.dev.raw.cmd_set_scissor(self.cmd, 0, &sc);
        }
    }

    fn bound(&self) -> Result<&'p Pipeline> {
        self.pipeline.ok_or(GpuError::Internal("draw without a bound pipeline"))
    }

    /// Binds textures (sampled with `texelFetch`) to set-0 bindings. Each must have been
    /// listed in the pass's `reads`.
    pub fn textures(&mut self, bindings: &[(u32, &Texture)]) -> Result<()> {
        let p = self.bound()?;
        let mut infos = Vec::with_capacity(bindings.len());
        for &(b, tex) in bindings {
            let Some(&BindingKind::Texture { arrayed }) = p.bindings.get(&b) else {
                return Err(GpuError::Usage(format!("binding {b} is not a texture in the bound pipeline")));
            };
            if !self.reads.iter().any(|r| std::ptr::eq(*r, tex)) {
                return Err(GpuError::Usage(format!(
                    "texture for binding {b} was not listed in the pass's reads"
                )));
            }
            infos.push([vk::DescriptorImageInfo {
                sampler: self.dev.sampler,
                image_view: if arrayed { tex.array_view } else { tex.view },
                image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            }]);
        }
        let writes: Vec<_> = bindings
            .iter()
            .zip(&infos)
            .map(|(&(b, _), info)| {
                vk::WriteDescriptorSet::default()
                    .dst_binding(b)
                    .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                    .image_info(info)
            })
            .collect();
        // SAFETY: views and sampler are alive for the submission.
        unsafe { self.push_descriptors(p, &writes) };
        Ok(())
    }

    /// Pushes set-0 descriptors of the bound pipeline `p`.
    ///
    /// # Safety
    /// What `writes` names must stay alive for the submission.
    unsafe fn push_descriptors(&self, p: &Pipeline, writes: &[vk::WriteDescriptorSet]) {
        // SAFETY: the layout is the bound pipeline's; the caller keeps the resources alive.
        unsafe {
            self.dev.push_descriptor.cmd_push_descriptor_set(
                self.cmd,
                vk::PipelineBindPoint::GRAPHICS,
                p.layout,
                0,
                writes,
            )
        }
    }

    /// Binds a uniform block at set-0 binding `binding`.
    pub fn uniform(&mut self, binding: u32, buffer: &Buffer) -> Result<()> {
        let p = self.bound()?;
        if p.bindings.get(&binding) != Some(&BindingKind::Uniform) {
            return Err(GpuError::Usage(format!(
                "binding {binding} is not a uniform block in the bound pipeline"
            )));
        }
        let info = [vk::DescriptorBufferInfo { buffer: buffer.raw, offset: 0, range: vk::WHOLE_SIZE }];
        let write = [vk::WriteDescriptorSet::default()
            .dst_binding(binding)
            .descriptor_type(vk::DescriptorType::UNIFORM_BUFFER)
            .buffer_info(&info)];
        // SAFETY: the buffer is alive for the submission.
        unsafe { self.push_descriptors(p, &write) };
        Ok(())
    }

    /// Sets the push constants (the shaders' `push_constant` block, from offset 0).
    pub fn push<T: Pod>(&mut self, data: &[T]) -> Result<()> {
        let p = self.bound()?;
        let bytes = as_bytes(data);
        let Some((stages, offset, size)) = p.push else {
            return Err(GpuError::Internal("push constants for a pipeline without any"));
        };
        if offset != 0 || bytes.len() as u32 != size {
            return Err(GpuError::Usage(format!(
                "push constants of {} bytes, but the shaders declare {size} bytes at offset {offset}",
                bytes.len()
            )));
        }
        // SAFETY: range and stages match the pipeline layout.
        unsafe { self.dev.raw.cmd_push_constants(self.cmd, p.layout, stages, 0, bytes) };
        Ok(())
    }

    /// Binds the per-vertex (and, when the pipeline has per-instance inputs, per-instance)
    /// vertex buffers.
    pub fn vertex_buffers(&mut self, per_vertex: &Buffer, per_instance: Option<&Buffer>) -> Result<()> {
        self.vertex_buffers_at(Some((per_vertex, 0)), per_instance.map(|b| (b, 0)))
    }

    /// Binds vertex buffers starting at byte offsets; `None` where the pipeline has no
    /// inputs of that rate (per vertex, per instance).
    pub fn vertex_buffers_at(
        &mut self,
        per_vertex: Option<(&Buffer, u64)>,
        per_instance: Option<(&Buffer, u64)>,
    ) -> Result<()> {
        let strides = self.bound()?.strides;
        let bind = |binding: u32, stride: u32, buffer: Option<(&Buffer, u64)>, what: &str| -> Result<()> {
            match (stride > 0, buffer) {
                (true, Some((b, offset))) => {
                    if offset >= b.size() {
                        return Err(GpuError::Usage(format!("{what} buffer offset {offset} past its end")));
                    }
                    // SAFETY: buffer alive for the submission; offset inside it.
                    unsafe { self.dev.raw.cmd_bind_vertex_buffers(self.cmd, binding, &[b.raw], &[offset]) };
                    Ok(())
                }
                (false, None) => Ok(()),
                (true, None) => Err(GpuError::Usage(format!("the pipeline needs a {what} buffer"))),
                // A buffer for inputs the pipeline lacks is ignored only when it is the
                // per-vertex one of a vertex-less pipeline (e.g. a full-target quad).
                (false, Some(_)) => Err(GpuError::Usage(format!("the pipeline has no {what} inputs"))),
            }
        };
        bind(0, strides[0], per_vertex, "per-vertex")?;
        bind(1, strides[1], per_instance, "per-instance")
    }

    /// Draws `vertices` vertices (points or triangle corners), `instances` times.
    ///
    /// lavapipe (Mesa 22.3) draws nothing of a triangle list of exactly 9 vertices whose
    /// last triangle is degenerate, and it cuts long triangle-list draws into segments of
    /// [`TRIANGLE_SEGMENT`] vertices, so a draw of 4095·q + 9 vertices loses its last
    /// three triangles the same way (`tests/gpu_core.rs` shows both). The voxelizer's
    /// culled cross-sections are such degenerate triangles: a zone list of 4104 vertices
    /// dropped voxels. Such draws are split so no draw or segment holds 9 vertices.
    pub fn draw(&mut self, vertices: std::ops::Range<u32>, instances: std::ops::Range<u32>) -> Result<()> {
        let pipeline = self.bound()?;
        let count = vertices.end.saturating_sub(vertices.start);
        if pipeline.topology == Topology::Triangles && count % TRIANGLE_SEGMENT == 9 {
            // 6 + 3 vertices, or (4095·q − 3) + 12: every part's last segment is safe.
            let split = vertices.end - if count == 9 { 3 } else { 12 };
            self.draw_once(vertices.start..split, instances.clone());
            self.draw_once(split..vertices.end, instances);
        } else {
            self.draw_once(vertices, instances);
        }
        Ok(())
    }

    fn draw_once(&mut self, vertices: std::ops::Range<u32>, instances: std::ops::Range<u32>) {
        if vertices.is_empty() || instances.is_empty() {
            return;
        }
        // SAFETY: pipeline bound (checked by `draw`); vertex buffers are the caller's
        // responsibility (validation checks).
        unsafe {
            self.dev.raw.cmd_draw(
                self.cmd,
                vertices.end - vertices.start,
                instances.end - instances.start,
                vertices.start,
                instances.start,
            )
        };
    }

    /// Binds `buffer` (u32 indices) for [`RenderScope::draw_indexed`].
    pub fn index_buffer(&mut self, buffer: &Buffer) -> Result<()> {
        self.bound()?;
        // SAFETY: buffer alive for the submission; made with index-buffer usage.
        unsafe { self.dev.raw.cmd_bind_index_buffer(self.cmd, buffer.raw, 0, vk::IndexType::UINT32) };
        Ok(())
    }

    /// Draws the vertices listed at `indices` of the bound index buffer, `instances` times.
    pub fn draw_indexed(
        &mut self,
        indices: std::ops::Range<u32>,
        instances: std::ops::Range<u32>,
    ) -> Result<()> {
        self.bound()?;
        if indices.is_empty() || instances.is_empty() {
            return Ok(());
        }
        // SAFETY: pipeline bound; index and vertex buffers are the caller's responsibility
        // (validation checks).
        unsafe {
            self.dev.raw.cmd_draw_indexed(
                self.cmd,
                indices.end - indices.start,
                instances.end - instances.start,
                indices.start,
                0,
                instances.start,
            )
        };
        Ok(())
    }

    /// The full-target quad: one fragment per texel of the viewport.
    pub fn quad(&mut self) -> Result<()> {
        self.draw(0..3, 0..1)
    }
}

/// Two same-sized render targets used alternately: pass *i* writes `dst()` while
/// sampling `src()`; `swap()` between passes.
pub struct PingPong {
    pair: [Texture; 2],
    current: usize,
}

impl PingPong {
    pub fn new(
        ctx: &super::Context,
        format: TexFormat,
        width: u32,
        height: u32,
        name: &str,
    ) -> Result<PingPong> {
        PingPong::new_layered(ctx, format, width, height, 1, name)
    }

    /// A pair of `layers`-layer targets.
    pub fn new_layered(
        ctx: &super::Context,
        format: TexFormat,
        width: u32,
        height: u32,
        layers: u32,
        name: &str,
    ) -> Result<PingPong> {
        Ok(PingPong {
            pair: [
                Texture::new_layered(ctx, format, width, height, layers, &format!("{name} ping"))?,
                Texture::new_layered(ctx, format, width, height, layers, &format!("{name} pong"))?,
            ],
            current: 0,
        })
    }

    /// The texture the last pass wrote (the next pass's input).
    pub fn src(&self) -> &Texture {
        &self.pair[self.current]
    }

    /// The texture the next pass writes.
    pub fn dst(&self) -> &Texture {
        &self.pair[1 - self.current]
    }

    pub fn swap(&mut self) {
        self.current = 1 - self.current;
    }

    pub fn width(&self) -> u32 {
        self.pair[0].width()
    }

    pub fn height(&self) -> u32 {
        self.pair[0].height()
    }
}
