//! `texgeo info`: the device, its driver and the limits texture-era algorithms hit.

use texgeo::gpu::{DeviceInfo, list_devices};

#[derive(clap::Args)]
pub struct Args {
    /// List every Vulkan device, not only the one texgeo would use.
    #[arg(long)]
    all: bool,
    /// Print one JSON object instead: `{"device": {…}, "validation": bool}`, or with --all
    /// `{"devices": [{…}, …]}`.
    #[arg(long)]
    json: bool,
}

fn yes(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}

fn print(d: &DeviceInfo) {
    say!("device: {} (index {}, {})", d.name, d.index, d.kind);
    say!("driver: {} {}", d.driver, d.driver_info);
    say!("Vulkan API: {}", d.api_version);
    say!("logicOp: {}", yes(d.logic_op));
    say!(
        "max texture size: {0}x{0} (2D), {1} layers, {2}^3 (3D)",
        d.max_image_2d,
        d.max_array_layers,
        d.max_image_3d
    );
    say!("color attachments: {}", d.max_color_attachments);
    say!("push constants: {} bytes; vertex attributes: {}", d.max_push_constants, d.max_vertex_attributes);
    say!("shaderFloat64: {}", yes(d.float64));
    say!("timestamps: {} ({} ns per tick)", yes(d.timestamps), d.timestamp_period_ns);
    say!(
        "dynamic rendering + synchronization2: {}; push descriptors: {}",
        yes(d.vulkan13),
        yes(d.push_descriptor)
    );
    if !d.masked.is_empty() {
        say!("masked by TEXGEO_MASK_FEATURES: {}", d.masked.join(", "));
    }
}

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    if args.all && args.json {
        texgeo::json::print(&serde_json::json!({ "devices": list_devices()? }));
        return Ok(());
    }
    if args.all {
        for (i, d) in list_devices()?.iter().enumerate() {
            if i > 0 {
                say!();
            }
            print(d);
        }
        return Ok(());
    }
    let ctx = crate::open_context(device)?;
    if args.json {
        texgeo::json::print(&serde_json::json!({ "device": ctx.info(), "validation": ctx.validating() }));
        return Ok(());
    }
    print(ctx.info());
    say!(
        "validation layer: {}",
        if ctx.validating() { "on" } else { "off (TEXGEO_VALIDATION=1 turns it on)" }
    );
    Ok(())
}
