//! `texgeo view MODEL [MORE…]`: the interactive viewer. Mouse: left-drag
//! orbits, right/middle- or shift-left-drag pans, the wheel zooms; keys: `+`/`-` level
//! (GPU fragment passes), `v` valence colours, `w` wireframe, `f` flat/smooth, `p` Perlin
//! aspect (voxels), `r` reset view, `s` screenshot, `q`/Esc quit.

use std::path::PathBuf;

use anyhow::bail;
use texgeo::gpu::{ContextOptions, DeviceChoice};
use texgeo::view::{self, Options};

use crate::render::Show;

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    show: Show,
    /// Draw this many frames, then exit (for scripts and tests).
    #[arg(long)]
    frames: Option<u64>,
    /// With --frames: save the last frame, as presented, to this PNG.
    #[arg(long)]
    screenshot: Option<PathBuf>,
    /// Steps applied one per frame, separated by commas: keys `+ - v w f r s p`,
    /// `orbit:DX:DY` (degrees), `pan:DX:DY` (picture heights), `zoom:F` (distance factor),
    /// `size:WxH`, `hide`, `show`, `minimize`, `restore`, `wait[:N]` (frames). Example:
    /// `--script 'orbit:90:0,zoom:0.5,+,+,v,s'` turns the camera, moves closer, goes two
    /// levels up, colours by valence and saves a screenshot.
    #[arg(long, allow_hyphen_values = true)]
    script: Option<String>,
    /// On exit, write the mesh on screen (at the level shown) to this file.
    #[arg(long)]
    save_mesh: Option<PathBuf>,
}

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    let show = &args.show;
    show.check()?;
    // Every output is checked before the window opens, like every other command's.
    if let Some(path) = &args.screenshot {
        if args.frames.is_none() {
            bail!(
                "--screenshot saves the last of --frames N frames; add --frames (or press `s` in the window)"
            );
        }
        texgeo::output::check_extension(path, &["png"], "screenshots are PNG")?;
        texgeo::output::check_output(path, &show.inputs())?;
    }
    if let Some(path) = &args.save_mesh {
        texgeo::mesh::formats::Format::from_path(path)?;
        texgeo::output::check_output(path, &show.inputs())?;
    }
    if args.frames == Some(0) {
        bail!("--frames must be at least 1");
    }
    let script = match &args.script {
        Some(s) => view::parse_script(s)?,
        None => Vec::new(),
    };
    let content = show.content()?;
    let options = Options {
        name: show.name(),
        context: ContextOptions { device: DeviceChoice::from_env_or(device), validation: None },
        size: show.size,
        samples: show.samples,
        yaw: show.yaw.to_radians(),
        pitch: show.pitch.to_radians(),
        level: show.level,
        look: show.look(),
        aspect: show.aspect(),
        frames: args.frames,
        screenshot: args.screenshot.clone(),
        script,
        save_mesh: args.save_mesh.clone(),
    };
    Ok(view::run(options, content)?)
}
