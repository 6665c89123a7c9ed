//! Graphics pipelines built from reflected SPIR-V: the descriptor set layout, the push
//! constant range and the vertex input layout all come from the shaders themselves
//! (rspirv-reflect), never from hand-written tables that could drift from the GLSL.

use std::collections::BTreeMap;
use std::sync::Arc;

use ash::vk;
use rspirv_reflect::rspirv::dr::{Instruction, Operand};
use rspirv_reflect::rspirv::spirv::{Decoration, Op, StorageClass};
use rspirv_reflect::{BindingCount, DescriptorType, Reflection};

use super::context::{Context, Device};
use super::error::{GpuError, Result, VkContext};
use super::texture::TexFormat;
use super::{Shader, shaders};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Topology {
    /// One point per datum (`gl_PointSize = 1`), each placed on its own texel.
    Points,
    Triangles,
}

/// What the fixed-function output stage does with a fragment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blend {
    /// Overwrite.
    Replace,
    /// Logic op XOR (integer targets only): parity accumulation.
    Xor,
    /// Additive blending (float targets): sum accumulation.
    Add,
}

/// How to build a pipeline. Vertex attributes are packed in location order into binding 0
/// (per vertex), except the locations listed in `per_instance`, packed into binding 1.
pub struct PipelineDesc<'a> {
    pub vertex: &'a Shader,
    pub fragment: &'a Shader,
    pub topology: Topology,
    pub targets: &'a [TexFormat],
    pub blend: Blend,
    pub per_instance: &'a [u32],
}

impl<'a> PipelineDesc<'a> {
    /// A pipeline whose vertex inputs all advance per vertex.
    pub fn new(
        vertex: &'a Shader,
        fragment: &'a Shader,
        topology: Topology,
        targets: &'a [TexFormat],
        blend: Blend,
    ) -> PipelineDesc<'a> {
        PipelineDesc { vertex, fragment, topology, targets, blend, per_instance: &[] }
    }

    /// The vertex input locations that advance per instance instead.
    pub fn per_instance(self, locations: &'a [u32]) -> PipelineDesc<'a> {
        PipelineDesc { per_instance: locations, ..self }
    }
}

/// Fixed-function state of pipelines that draw pictures (depth-tested, possibly
/// multisampled); `Raster::default()` is what the GPGPU passes use: no depth buffer, one
/// sample, no culling.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Raster {
    /// Depth test against a `Depth32F` target: `Less` for surfaces, `LessOrEqual` for
    /// lines drawn over them; every tested fragment that passes writes its depth.
    pub depth: DepthTest,
    /// Samples per pixel of the targets (1 = no multisampling).
    pub samples: u32,
}

impl Default for Raster {
    fn default() -> Raster {
        Raster { depth: DepthTest::Off, samples: 1 }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthTest {
    /// No depth buffer.
    Off,
    Less,
    LessOrEqual,
}

/// A descriptor binding the pipeline expects (set 0, pushed per draw).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BindingKind {
    /// A sampled texture; `arrayed` for `sampler2DArray` (bound through the array view).
    Texture {
        arrayed: bool,
    },
    Uniform,
}

pub struct Pipeline {
    dev: Arc<Device>,
    pub(crate) raw: vk::Pipeline,
    pub(crate) layout: vk::PipelineLayout,
    set_layout: vk::DescriptorSetLayout,
    pub(crate) bindings: BTreeMap<u32, BindingKind>,
    pub(crate) push: Option<(vk::ShaderStageFlags, u32, u32)>,
    pub(crate) targets: Vec<TexFormat>,
    /// Depth format of the pass (`None`: no depth buffer) and samples per pixel.
    pub(crate) depth: Option<TexFormat>,
    pub(crate) samples: u32,
    /// Byte strides of binding 0 (per vertex) and binding 1 (per instance).
    pub(crate) strides: [u32; 2],
    pub(crate) topology: Topology,
    pub(crate) name: String,
}

struct Reflected {
    sets: BTreeMap<u32, BTreeMap<u32, rspirv_reflect::DescriptorInfo>>,
    push: Option<(u32, u32)>,
}

fn reflect(shader: &Shader) -> Result<(Reflection, Reflected)> {
    let err = |m: String| GpuError::Shader { shader: shader.path.to_string(), message: m };
    let r = Reflection::new_from_spirv(shader.spirv).map_err(|e| err(format!("cannot parse SPIR-V: {e}")))?;
    let sets = r.get_descriptor_sets().map_err(|e| err(format!("reflection: {e}")))?;
    let push =
        r.get_push_constant_range().map_err(|e| err(format!("reflection: {e}")))?.map(|p| (p.offset, p.size));
    Ok((r, Reflected { sets, push }))
}

fn refl_module<'a>(mods: &[&'a Reflection; 2], stage: vk::ShaderStageFlags) -> &'a Reflection {
    if stage == vk::ShaderStageFlags::VERTEX { mods[0] } else { mods[1] }
}

/// Whether the sampler at set 0, `binding` is an array image (`sampler2DArray`).
fn texture_is_arrayed(shader: &Shader, r: &Reflection, binding: u32) -> Result<bool> {
    let err = |m: String| GpuError::Shader { shader: shader.path.to_string(), message: m };
    let m = &r.0;
    let by_id: BTreeMap<u32, &Instruction> =
        m.types_global_values.iter().filter_map(|i| Some((i.result_id?, i))).collect();
    let target = m.annotations.iter().find_map(|a| match a.operands.as_slice() {
        [Operand::IdRef(t), Operand::Decoration(Decoration::Binding), Operand::LiteralBit32(b)]
            if a.class.opcode == Op::Decorate && *b == binding =>
        {
            Some(*t)
        }
        _ => None,
    });
    let ty =
        target.and_then(|t| by_id.get(&t)).and_then(|v| v.result_type).and_then(|p| by_id.get(&p)).and_then(
            |p| match p.operands.as_slice() {
                [Operand::StorageClass(_), Operand::IdRef(t)] => by_id.get(t),
                _ => None,
            },
        );
    let image = match ty {
        Some(t) if t.class.opcode == Op::TypeSampledImage => match t.operands.as_slice() {
            [Operand::IdRef(i)] => by_id.get(i),
            _ => None,
        },
        _ => None,
    };
    match image.map(|i| i.operands.as_slice()) {
        Some([_, Operand::Dim(_), _, Operand::LiteralBit32(arrayed), ..]) => Ok(*arrayed == 1),
        _ => Err(err(format!("binding {binding}: cannot find its sampled image type"))),
    }
}

/// A vertex shader input: location and Vulkan format.
#[derive(Clone, Copy, Debug)]
struct VertexInput {
    location: u32,
    format: vk::Format,
    bytes: u32,
}

/// The vertex shader's `in` variables (builtins excluded), from the SPIR-V module.
fn vertex_inputs(shader: &Shader, r: &Reflection) -> Result<Vec<VertexInput>> {
    let err = |m: String| GpuError::Shader { shader: shader.path.to_string(), message: m };
    let m = &r.0;
    let by_id: BTreeMap<u32, &Instruction> =
        m.types_global_values.iter().filter_map(|i| Some((i.result_id?, i))).collect();
    let mut locations = BTreeMap::new();
    for a in &m.annotations {
        if a.class.opcode != Op::Decorate {
            continue;
        }
        if let [
            Operand::IdRef(target),
            Operand::Decoration(Decoration::Location),
            Operand::LiteralBit32(loc),
            ..,
        ] = a.operands.as_slice()
        {
            locations.insert(*target, *loc);
        }
    }
    let mut inputs = Vec::new();
    for v in m.types_global_values.iter().filter(|i| i.class.opcode == Op::Variable) {
        if !matches!(v.operands.first(), Some(Operand::StorageClass(StorageClass::Input))) {
            continue;
        }
        let (Some(id), Some(ptr)) = (v.result_id, v.result_type) else { continue };
        let Some(&location) = locations.get(&id) else { continue }; // builtins have no location
        let pointee = match by_id.get(&ptr).map(|p| p.operands.as_slice()) {
            Some([Operand::StorageClass(_), Operand::IdRef(t)]) => *t,
            _ => return Err(err(format!("input at location {location} is not a pointer variable"))),
        };
        let (scalar, count) = match by_id.get(&pointee) {
            Some(t) if t.class.opcode == Op::TypeVector => match t.operands.as_slice() {
                [Operand::IdRef(c), Operand::LiteralBit32(n)] => (*c, *n),
                _ => return Err(err(format!("malformed vector type at location {location}"))),
            },
            Some(_) => (pointee, 1),
            None => return Err(err(format!("unknown type at location {location}"))),
        };
        let kind = match by_id.get(&scalar).map(|t| (t.class.opcode, t.operands.as_slice())) {
            Some((Op::TypeFloat, [Operand::LiteralBit32(32), ..])) => 'f',
            Some((Op::TypeInt, [Operand::LiteralBit32(32), Operand::LiteralBit32(0)])) => 'u',
            Some((Op::TypeInt, [Operand::LiteralBit32(32), Operand::LiteralBit32(1)])) => 'i',
            _ => return Err(err(format!("input at location {location} is not a 32-bit scalar or vector"))),
        };
        use vk::Format as F;
        let format = match (kind, count) {
            ('f', 1) => F::R32_SFLOAT,
            ('f', 2) => F::R32G32_SFLOAT,
            ('f', 3) => F::R32G32B32_SFLOAT,
            ('f', 4) => F::R32G32B32A32_SFLOAT,
            ('u', 1) => F::R32_UINT,
            ('u', 2) => F::R32G32_UINT,
            ('u', 3) => F::R32G32B32_UINT,
            ('u', 4) => F::R32G32B32A32_UINT,
            ('i', 1) => F::R32_SINT,
            ('i', 2) => F::R32G32_SINT,
            ('i', 3) => F::R32G32B32_SINT,
            ('i', 4) => F::R32G32B32A32_SINT,
            _ => return Err(err(format!("unsupported input type at location {location}"))),
        };
        inputs.push(VertexInput { location, format, bytes: 4 * count });
    }
    inputs.sort_by_key(|i| i.location);
    Ok(inputs)
}

/// Descriptor bindings of set 0: binding → (kind, stages that use it).
type Bindings = BTreeMap<u32, (BindingKind, vk::ShaderStageFlags)>;

/// Refuses a target list the device or the blend cannot serve: XOR needs the logicOp
/// feature and integer targets; the count must be within the device's colour attachments.
fn check_targets(dev: &Device, desc: &PipelineDesc, name: &str) -> Result<()> {
    if desc.blend == Blend::Xor {
        if !dev.info.logic_op {
            return Err(GpuError::Unsupported(format!("device '{}' has no logicOp feature", dev.info.name)));
        }
        if let Some(f) = desc.targets.iter().find(|f| !f.is_integer()) {
            return Err(GpuError::Usage(format!("{name}: logic op XOR needs integer targets, not {f:?}")));
        }
    }
    if desc.targets.is_empty() || desc.targets.len() > dev.info.max_color_attachments as usize {
        return Err(GpuError::Usage(format!(
            "{name}: {} targets (the device allows 1..={})",
            desc.targets.len(),
            dev.info.max_color_attachments
        )));
    }
    Ok(())
}

/// The descriptor bindings of both stages (`mods` and `refl`: vertex, fragment): set 0
/// only, pushed per draw; textures and uniform blocks only — storage resources would
/// break the texture-era model (SPEC §0). A binding both stages use must agree in kind.
fn descriptor_bindings(
    desc: &PipelineDesc,
    mods: [&Reflection; 2],
    refl: [&Reflected; 2],
) -> Result<Bindings> {
    let mut bindings = Bindings::new();
    for (stage, refl, shader) in [
        (vk::ShaderStageFlags::VERTEX, refl[0], desc.vertex),
        (vk::ShaderStageFlags::FRAGMENT, refl[1], desc.fragment),
    ] {
        for (&set, set_bindings) in &refl.sets {
            let err = |m: String| GpuError::Shader { shader: shader.path.to_string(), message: m };
            if set != 0 {
                return Err(err(format!("uses descriptor set {set}; texgeo shaders use set 0 only")));
            }
            for (&b, info) in set_bindings {
                let kind = match info.ty {
                    DescriptorType::COMBINED_IMAGE_SAMPLER => BindingKind::Texture {
                        arrayed: texture_is_arrayed(shader, refl_module(&mods, stage), b)?,
                    },
                    DescriptorType::UNIFORM_BUFFER => BindingKind::Uniform,
                    other => {
                        return Err(err(format!(
                            "binding {b} is {other:?}; only sampled textures and uniform blocks are allowed"
                        )));
                    }
                };
                if info.binding_count != BindingCount::One {
                    return Err(err(format!("binding {b} is an array; bind textures one by one")));
                }
                let entry = bindings.entry(b).or_insert((kind, vk::ShaderStageFlags::empty()));
                if entry.0 != kind {
                    return Err(err(format!("binding {b} has different types in the two stages")));
                }
                entry.1 |= stage;
            }
        }
    }
    Ok(bindings)
}

/// One push-constant range over both stages' (offset, size): (stages, offset, size).
fn push_range(
    vertex: Option<(u32, u32)>,
    fragment: Option<(u32, u32)>,
) -> Option<(vk::ShaderStageFlags, u32, u32)> {
    if vertex.is_none() && fragment.is_none() {
        return None;
    }
    let mut stages = vk::ShaderStageFlags::empty();
    let (mut lo, mut hi) = (u32::MAX, 0);
    for (s, r) in [(vk::ShaderStageFlags::VERTEX, vertex), (vk::ShaderStageFlags::FRAGMENT, fragment)] {
        if let Some((off, size)) = r {
            stages |= s;
            lo = lo.min(off);
            hi = hi.max(off + size);
        }
    }
    Some((stages, lo, hi - lo))
}

/// The vertex buffers' layout: binding 0 per vertex, binding 1 per instance (the
/// locations in `per_instance`), attributes packed in location order.
struct VertexLayout {
    strides: [u32; 2],
    attributes: Vec<vk::VertexInputAttributeDescription>,
    bindings: Vec<vk::VertexInputBindingDescription>,
}

impl VertexLayout {
    fn new(desc: &PipelineDesc, inputs: &[VertexInput]) -> VertexLayout {
        let mut strides = [0u32; 2];
        let mut attributes = Vec::new();
        for i in inputs {
            let binding = u32::from(desc.per_instance.contains(&i.location));
            attributes.push(
                vk::VertexInputAttributeDescription::default()
                    .location(i.location)
                    .binding(binding)
                    .format(i.format)
                    .offset(strides[binding as usize]),
            );
            strides[binding as usize] += i.bytes;
        }
        let mut bindings = Vec::new();
        for (b, rate) in [vk::VertexInputRate::VERTEX, vk::VertexInputRate::INSTANCE].into_iter().enumerate()
        {
            if strides[b] > 0 {
                bindings.push(
                    vk::VertexInputBindingDescription::default()
                        .binding(b as u32)
                        .stride(strides[b])
                        .input_rate(rate),
                );
            }
        }
        VertexLayout { strides, attributes, bindings }
    }
}

/// One blend state per target: additive for [`Blend::Add`], none otherwise (XOR is the
/// logic op, set on the whole blend state).
fn blend_attachments(desc: &PipelineDesc) -> Vec<vk::PipelineColorBlendAttachmentState> {
    desc.targets
        .iter()
        .map(|_| {
            let a = vk::PipelineColorBlendAttachmentState::default()
                .color_write_mask(vk::ColorComponentFlags::RGBA);
            match desc.blend {
                Blend::Add => a
                    .blend_enable(true)
                    .src_color_blend_factor(vk::BlendFactor::ONE)
                    .dst_color_blend_factor(vk::BlendFactor::ONE)
                    .color_blend_op(vk::BlendOp::ADD)
                    .src_alpha_blend_factor(vk::BlendFactor::ONE)
                    .dst_alpha_blend_factor(vk::BlendFactor::ONE)
                    .alpha_blend_op(vk::BlendOp::ADD),
                Blend::Replace | Blend::Xor => a,
            }
        })
        .collect()
}

impl Pipeline {
    pub fn new(ctx: &Context, desc: &PipelineDesc) -> Result<Pipeline> {
        Pipeline::with_raster(ctx, desc, &Raster::default())
    }

    /// A pipeline with a depth test and/or multisampling (see [`Raster`]): the targets
    /// checked, the shaders reflected (descriptor bindings, push constants, vertex
    /// inputs), then the layouts and the pipeline created.
    pub fn with_raster(ctx: &Context, desc: &PipelineDesc, state: &Raster) -> Result<Pipeline> {
        let dev = ctx.dev.clone();
        let name = format!("{} + {}", desc.vertex.path, desc.fragment.path);
        check_targets(&dev, desc, &name)?;
        let (vr, v) = reflect(desc.vertex)?;
        let (fr, f) = reflect(desc.fragment)?;
        let bindings = descriptor_bindings(desc, [&vr, &fr], [&v, &f])?;
        let push = push_range(v.push, f.push);
        let vertex = VertexLayout::new(desc, &vertex_inputs(desc.vertex, &vr)?);
        let mut pipeline = Pipeline {
            dev: dev.clone(),
            raw: vk::Pipeline::null(),
            layout: vk::PipelineLayout::null(),
            set_layout: vk::DescriptorSetLayout::null(),
            bindings: bindings.iter().map(|(&b, &(k, _))| (b, k)).collect(),
            push,
            targets: desc.targets.to_vec(),
            depth: (state.depth != DepthTest::Off).then_some(TexFormat::Depth32F),
            samples: state.samples,
            strides: vertex.strides,
            topology: desc.topology,
            name,
        };
        // From here on, Drop of `pipeline` destroys whatever was created if a step fails.
        pipeline.create_layouts(&bindings)?;
        pipeline.create_raw(desc, state, &vertex)?;
        Ok(pipeline)
    }

    /// The descriptor set layout (set 0, pushed per draw) and the pipeline layout.
    fn create_layouts(&mut self, bindings: &Bindings) -> Result<()> {
        let layout_bindings: Vec<_> = bindings
            .iter()
            .map(|(&b, &(kind, stages))| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b)
                    .descriptor_type(match kind {
                        BindingKind::Texture { .. } => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                        BindingKind::Uniform => vk::DescriptorType::UNIFORM_BUFFER,
                    })
                    .descriptor_count(1)
                    .stage_flags(stages)
            })
            .collect();
        let set_info = vk::DescriptorSetLayoutCreateInfo::default()
            .flags(vk::DescriptorSetLayoutCreateFlags::PUSH_DESCRIPTOR_KHR)
            .bindings(&layout_bindings);
        let dev = &self.dev;
        // SAFETY: valid device and create infos; handles are owned by `self`.
        self.set_layout = unsafe { dev.raw.create_descriptor_set_layout(&set_info, None) }
            .vk("vkCreateDescriptorSetLayout")?;
        let ranges: Vec<_> = self
            .push
            .iter()
            .map(|&(stages, offset, size)| vk::PushConstantRange { stage_flags: stages, offset, size })
            .collect();
        let set_layouts = [self.set_layout];
        let layout_info =
            vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts).push_constant_ranges(&ranges);
        // SAFETY: as above.
        self.layout =
            unsafe { dev.raw.create_pipeline_layout(&layout_info, None) }.vk("vkCreatePipelineLayout")?;
        Ok(())
    }

    /// The graphics pipeline itself: shader stages, fixed-function state (after checking
    /// the device offers the samples asked for), dynamic rendering formats.
    fn create_raw(&mut self, desc: &PipelineDesc, state: &Raster, vertex: &VertexLayout) -> Result<()> {
        let dev = self.dev.clone();
        let vmod = ShaderModule::new(&dev, desc.vertex)?;
        let fmod = ShaderModule::new(&dev, desc.fragment)?;
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vmod.raw)
                .name(c"main"),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(fmod.raw)
                .name(c"main"),
        ];
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
            .vertex_binding_descriptions(&vertex.bindings)
            .vertex_attribute_descriptions(&vertex.attributes);
        let assembly = vk::PipelineInputAssemblyStateCreateInfo::default().topology(match desc.topology {
            Topology::Points => vk::PrimitiveTopology::POINT_LIST,
            Topology::Triangles => vk::PrimitiveTopology::TRIANGLE_LIST,
        });
        let viewport = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(vk::CullModeFlags::NONE)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        if !state.samples.is_power_of_two() || dev.info.colour_samples & state.samples == 0 {
            return Err(GpuError::Unsupported(format!(
                "{}: device '{}' offers no {}-sample targets",
                self.name, dev.info.name, state.samples
            )));
        }
        let multisample = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(vk::SampleCountFlags::from_raw(state.samples));
        let depth_state = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(state.depth != DepthTest::Off)
            .depth_write_enable(state.depth != DepthTest::Off)
            .depth_compare_op(match state.depth {
                DepthTest::LessOrEqual => vk::CompareOp::LESS_OR_EQUAL,
                _ => vk::CompareOp::LESS,
            });
        let attachments = blend_attachments(desc);
        let blend = vk::PipelineColorBlendStateCreateInfo::default()
            .logic_op_enable(desc.blend == Blend::Xor)
            .logic_op(vk::LogicOp::XOR)
            .attachments(&attachments);
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let formats: Vec<_> = desc.targets.iter().map(|f| f.vk()).collect();
        let mut rendering = vk::PipelineRenderingCreateInfo::default().color_attachment_formats(&formats);
        if let Some(d) = self.depth {
            rendering = rendering.depth_attachment_format(d.vk());
        }
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth_state)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(self.layout)
            .push_next(&mut rendering);
        // SAFETY: every pointer in `info` outlives the call; modules are alive until after it.
        // The device's cache (kept between runs); locked, as Vulkan wants a cache used by
        // one thread at a time.
        let cache = super::error::lock(&dev.pipeline_cache, "pipeline cache")?;
        let created = unsafe { dev.raw.create_graphics_pipelines(cache.raw, &[info], None) };
        drop(cache);
        self.raw =
            created.map_err(|(_, e)| GpuError::Vk { call: "vkCreateGraphicsPipelines", result: e })?[0];
        Ok(())
    }

    /// A full-target quad pass: the built-in quad vertex shader and `fragment`, which runs
    /// once per output texel (`gl_FragCoord.xy` is the texel centre).
    pub fn quad(ctx: &Context, fragment: &Shader, targets: &[TexFormat], blend: Blend) -> Result<Pipeline> {
        Pipeline::new(
            ctx,
            &PipelineDesc::new(&shaders::gpu::QUAD_VERT, fragment, Topology::Triangles, targets, blend),
        )
    }

    pub fn name(&self) -> &str {
        &self.name
    }
}

impl Drop for Pipeline {
    fn drop(&mut self) {
        // SAFETY: submissions wait for completion; null handles are ignored by Vulkan.
        unsafe {
            self.dev.raw.destroy_pipeline(self.raw, None);
            self.dev.raw.destroy_pipeline_layout(self.layout, None);
            self.dev.raw.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

/// A shader module that lives only while a pipeline is created.
struct ShaderModule<'a> {
    dev: &'a Device,
    raw: vk::ShaderModule,
}

impl<'a> ShaderModule<'a> {
    fn new(dev: &'a Device, shader: &Shader) -> Result<ShaderModule<'a>> {
        let words = ash::util::read_spv(&mut std::io::Cursor::new(shader.spirv))
            .map_err(|e| GpuError::Shader { shader: shader.path.to_string(), message: e.to_string() })?;
        let info = vk::ShaderModuleCreateInfo::default().code(&words);
        // SAFETY: valid SPIR-V produced by build.rs.
        let raw = unsafe { dev.raw.create_shader_module(&info, None) }.vk("vkCreateShaderModule")?;
        Ok(ShaderModule { dev, raw })
    }
}

impl Drop for ShaderModule<'_> {
    fn drop(&mut self) {
        // SAFETY: only used during pipeline creation, which has returned.
        unsafe { self.dev.raw.destroy_shader_module(self.raw, None) };
    }
}
