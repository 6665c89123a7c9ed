//! The window, its event loop and the frame loop.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::application::ApplicationHandler;
use winit::dpi::{PhysicalPosition, PhysicalSize};
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, ModifiersState, NamedKey};
use winit::window::{Window, WindowId};

use crate::gpu::{Context, ContextOptions, Presented, Surface, Swapchain};
use crate::render::{Camera, Content, Look, Model, Picture, Prepared, RenderError, Renderer, View, colour};
use crate::voxel::aspect::Aspect;

use super::error::{Result, ViewError};
use super::script::Step;

/// How to run the viewer.
#[derive(Clone, Debug)]
pub struct Options {
    /// Shown in the title.
    pub name: String,
    pub context: ContextOptions,
    /// Initial window size, pixels.
    pub size: [u32; 2],
    pub samples: u32,
    /// Initial camera angles, radians.
    pub yaw: f64,
    pub pitch: f64,
    pub level: u32,
    pub look: Look,
    /// Perlin aspect colours for voxel volumes (toggled with `p`).
    pub aspect: Option<Aspect>,
    /// Draw this many frames, then exit (headless use); `None`: until the window closes.
    pub frames: Option<u64>,
    /// Where the last frame goes when `frames` is set.
    pub screenshot: Option<PathBuf>,
    /// Steps applied one per frame before drawing.
    pub script: Vec<Step>,
    /// Writes the mesh on screen (at the level shown) here on exit.
    pub save_mesh: Option<PathBuf>,
}

/// Opens the window and runs until it is closed (or `options.frames` are drawn).
pub fn run(options: Options, content: Content) -> Result<()> {
    let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
    if var("DISPLAY").is_none() {
        return Err(ViewError::NoDisplay(if var("WAYLAND_DISPLAY").is_some() {
            "WAYLAND_DISPLAY is set but DISPLAY is not; the viewer talks X11 (XWayland sets DISPLAY)".into()
        } else {
            "neither DISPLAY nor WAYLAND_DISPLAY is set".into()
        }));
    }
    let event_loop =
        EventLoop::new().map_err(|e| ViewError::NoDisplay(format!("cannot connect to the X server: {e}")))?;
    let mut app = App::new(options, content);
    event_loop.run_app(&mut app).map_err(|e| ViewError::Window(e.to_string()))?;
    app.finish()
}

/// Device-side state: everything made from the window's context, dropped in field order
/// (pictures before the renderer, the swapchain before the surface, the context last).
struct Gfx {
    prepared: Option<Prepared>,
    renderer: Renderer,
    model: Model,
    swapchain: Option<Swapchain>,
    surface: Arc<Surface>,
    ctx: Context,
}

#[derive(Default)]
struct Mouse {
    position: Option<PhysicalPosition<f64>>,
    orbit: bool,
    pan: bool,
    modifiers: ModifiersState,
}

struct App {
    options: Options,
    content: Option<Content>,
    /// Declared before `window`: the surface goes before the window it shows.
    gfx: Option<Gfx>,
    window: Option<Window>,
    error: Option<ViewError>,
    camera: Option<Camera>,
    mouse: Mouse,
    /// Frames presented, and the script's position and pause.
    frames: u64,
    step: usize,
    waiting: u32,
    /// Camera steps of the script that came before there was a camera (the scene is
    /// prepared with the first frame): applied, in order, to the first camera.
    early_camera: Vec<Step>,
    /// The scene changed: rebuild the GPU buffers before the next frame.
    dirty: bool,
    /// The swapchain must be remade (resize, out of date).
    stale: bool,
    /// Save a screenshot with the next frame.
    shot: bool,
    shots: u32,
    last_frame: Option<Instant>,
    frame_time: Duration,
}

impl App {
    fn new(options: Options, content: Content) -> App {
        App {
            options,
            content: Some(content),
            gfx: None,
            window: None,
            error: None,
            camera: None,
            mouse: Mouse::default(),
            frames: 0,
            step: 0,
            waiting: 0,
            early_camera: Vec::new(),
            dirty: true,
            stale: true,
            shot: false,
            shots: 0,
            last_frame: None,
            frame_time: Duration::ZERO,
        }
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: ViewError) {
        if self.error.is_none() {
            self.error = Some(e);
        }
        event_loop.exit();
    }

    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let [w, h] = self.options.size;
        let attributes = Window::default_attributes()
            .with_title(format!("texgeo view — {}", self.options.name))
            .with_inner_size(PhysicalSize::new(w, h));
        let window = event_loop
            .create_window(attributes)
            .map_err(|e| ViewError::NoDisplay(format!("cannot open a window: {e}")))?;
        let display = window.display_handle().map_err(|e| ViewError::Window(e.to_string()))?.as_raw();
        let handle = window.window_handle().map_err(|e| ViewError::Window(e.to_string()))?.as_raw();
        let (ctx, surface) = Context::for_window(&self.options.context, display, handle)?;
        self.window = Some(window);
        crate::say!("device: {}", ctx.info().label());
        let content = self.content.take().ok_or_else(|| ViewError::Usage("nothing to show".into()))?;
        let model = Model::new(&ctx, content, self.options.level, self.options.look, self.options.aspect)?;
        let renderer = Renderer::new(&ctx, self.options.samples)?;
        self.gfx =
            Some(Gfx { prepared: None, renderer, model, swapchain: None, surface: Arc::new(surface), ctx });
        Ok(())
    }

    /// The window's inner size (zero while minimized).
    fn window_size(&self) -> [u32; 2] {
        self.window.as_ref().map(|w| w.inner_size()).map_or([0, 0], |s| [s.width, s.height])
    }

    fn reset_camera(&mut self) {
        let Some(gfx) = &self.gfx else { return };
        let Some(prepared) = &gfx.prepared else { return };
        let (lo, hi) = prepared.bounds();
        let [w, h] = self.window_size();
        let aspect = if w > 0 && h > 0 { f64::from(w) / f64::from(h) } else { 1.0 };
        self.camera = Some(Camera::fit(lo, hi, self.options.yaw, self.options.pitch, aspect));
    }

    fn redraw(&self) {
        if let Some(w) = &self.window {
            w.request_redraw();
        }
    }

    /// Applies a key; returns whether the picture changed.
    fn key(&mut self, key: char) -> Result<()> {
        let Some(gfx) = self.gfx.as_mut() else { return Ok(()) };
        let model = &mut gfx.model;
        match key {
            '+' | '-' if model.has_levels() => {
                let level = if key == '+' { model.level + 1 } else { model.level.saturating_sub(1) };
                if level != model.level {
                    match model.set_level(&gfx.ctx, level) {
                        Ok(line) => {
                            crate::say!("{line}");
                            self.dirty = true;
                        }
                        // A level that does not fit is a message, not the end of the session.
                        Err(e @ (RenderError::Usage(_) | RenderError::Subdiv(_))) => {
                            crate::note!("texgeo view: {e}")
                        }
                        Err(e) => return Err(e.into()),
                    }
                }
            }
            '+' | '-' => crate::say!("no subdivision levels for this content"),
            'v' if !model.is_voxels() => {
                model.look.valence = !model.look.valence;
                self.dirty = true;
            }
            'w' => {
                model.look.wireframe = !model.look.wireframe;
                self.dirty = true;
            }
            'f' => {
                model.toggle_shading();
                self.dirty = true;
            }
            'p' if model.is_voxels() => {
                model.show_aspect = !model.show_aspect;
                self.dirty = true;
            }
            'r' => self.reset_camera(),
            's' => self.shot = true,
            _ => {}
        }
        Ok(())
    }

    /// Runs the script's next step (one per frame).
    fn script_step(&mut self) -> Result<()> {
        if self.waiting > 0 {
            self.waiting -= 1;
            return Ok(());
        }
        let Some(step) = self.options.script.get(self.step).cloned() else { return Ok(()) };
        self.step += 1;
        let window = self.window.as_ref();
        match step {
            Step::Key(k) => self.key(k)?,
            Step::Orbit(..) | Step::Zoom(_) | Step::Pan(..) => match &mut self.camera {
                Some(camera) => apply_camera(camera, &step),
                None => self.early_camera.push(step),
            },
            Step::Size(w, h) => {
                if let Some(win) = window {
                    let _ = win.request_inner_size(PhysicalSize::new(w, h));
                }
            }
            Step::Hide => window.iter().for_each(|w| w.set_visible(false)),
            Step::Show => window.iter().for_each(|w| w.set_visible(true)),
            Step::Minimize => window.iter().for_each(|w| w.set_minimized(true)),
            Step::Restore => window.iter().for_each(|w| w.set_minimized(false)),
            Step::Wait(n) => self.waiting = n.saturating_sub(1),
        }
        Ok(())
    }

    fn script_done(&self) -> bool {
        self.step >= self.options.script.len() && self.waiting == 0
    }

    /// Draws and presents one frame; returns whether it was presented.
    fn frame(&mut self) -> Result<bool> {
        self.script_step()?;
        let size = self.window_size();
        let Some(gfx) = self.gfx.as_mut() else { return Ok(false) };
        if size[0] == 0 || size[1] == 0 {
            return Ok(false); // minimized: nothing to present to
        }
        if self.dirty {
            gfx.prepared = None;
            let scene = gfx.model.scene(&gfx.ctx)?;
            let prepared = gfx.renderer.prepare(&scene)?;
            gfx.prepared = Some(prepared);
            self.dirty = false;
            if self.camera.is_none() {
                self.reset_camera();
                if let Some(camera) = &mut self.camera {
                    for step in self.early_camera.drain(..) {
                        apply_camera(camera, &step);
                    }
                }
            }
            if self
                .gfx
                .as_ref()
                .and_then(|g| g.prepared.as_ref())
                .is_some_and(|p| p.triangles() + p.segments() == 0)
            {
                return Err(ViewError::Usage("nothing to show: the model has no faces".into()));
            }
        }
        let last = self.options.frames.is_some_and(|n| self.frames + 1 >= n) && self.script_done();
        let Some(gfx) = self.gfx.as_mut() else { return Ok(false) };
        if self.stale || gfx.swapchain.as_ref().is_none_or(|s| s.size() != size) {
            let old = gfx.swapchain.take();
            gfx.swapchain = Some(Swapchain::new(&gfx.ctx, &gfx.surface, size, old.as_ref())?);
            drop(old);
            self.stale = false;
        }
        let (Some(swapchain), Some(prepared), Some(camera)) =
            (gfx.swapchain.as_mut(), gfx.prepared.as_ref(), self.camera)
        else {
            return Ok(false);
        };
        let [w, h] = swapchain.size();
        let view = View { camera, width: w, height: h, background: colour::BACKGROUND };
        let capture = self.shot || (last && self.options.screenshot.is_some());
        let renderer = &mut gfx.renderer;
        let started = Instant::now();
        let (status, pixels) =
            swapchain.present(&gfx.ctx, capture, |rec| renderer.record(rec, prepared, &view))?;
        self.frame_time = started.elapsed();
        match status {
            Presented::Shown => {}
            Presented::Suboptimal => self.stale = true,
            Presented::OutOfDate => {
                self.stale = true;
                return Ok(false);
            }
        }
        if let Some(rgba) = pixels {
            let picture = Picture::new(w, h, rgba)?;
            if self.shot {
                self.shot = false;
                self.shots += 1;
                let path = loop {
                    let p = PathBuf::from(format!("texgeo-view-{:03}.png", self.shots));
                    if !p.exists() {
                        break p;
                    }
                    self.shots += 1;
                };
                picture.save_png(&path)?;
                crate::say!("wrote {}", path.display());
            }
            if let (true, Some(path)) = (last, &self.options.screenshot) {
                picture.save_png(path)?;
                crate::say!("wrote {} ({w}×{h})", path.display());
            }
        }
        Ok(true)
    }

    fn title(&mut self) {
        let (Some(window), Some(gfx)) = (&self.window, &self.gfx) else { return };
        let now = Instant::now();
        let fps = match self.last_frame {
            Some(t) if self.options.frames.is_some() => 1.0 / (now - t).as_secs_f64().max(1e-6),
            _ => 1.0 / self.frame_time.as_secs_f64().max(1e-6),
        };
        self.last_frame = Some(now);
        let (v, f) = gfx.model.counts();
        let what = if gfx.model.is_voxels() {
            format!("{f} voxels")
        } else {
            format!("level {}, {v} vertices, {f} faces", gfx.model.level)
        };
        let triangles = gfx.prepared.as_ref().map_or(0, Prepared::triangles);
        window.set_title(&format!(
            "texgeo view — {} — {what}, {triangles} triangles — {fps:.0} fps",
            self.options.name
        ));
    }

    /// Drops every GPU resource, then checks that nothing leaked and validation stayed quiet.
    fn finish(mut self) -> Result<()> {
        let saved = match (&self.options.save_mesh, self.gfx.as_ref().and_then(|g| g.model.shown_mesh())) {
            // The error names the path already.
            (Some(path), Some(mesh)) => {
                crate::mesh::formats::write(path, mesh).map_err(ViewError::from).map(|()| Some(path.clone()))
            }
            (Some(_), None) => Err(ViewError::Usage("--save-mesh needs a single mesh on screen".into())),
            _ => Ok(None),
        };
        let teardown = match self.gfx.take() {
            Some(gfx) => {
                let ctx = gfx.ctx.clone();
                drop(gfx);
                let live = ctx.live_allocations();
                let checked = ctx.check_validation().map_err(ViewError::from);
                if live > 0 { Err(ViewError::Leak(live)) } else { checked }
            }
            None => Ok(()),
        };
        drop(self.window.take());
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        teardown?;
        if let Some(path) = saved? {
            crate::say!("wrote {}", path.display());
        }
        Ok(())
    }
}

/// Applies a camera step of a script (orbit, zoom, pan; other steps do nothing here).
fn apply_camera(camera: &mut Camera, step: &Step) {
    match *step {
        Step::Orbit(a, b) => camera.orbit(a.to_radians(), b.to_radians()),
        Step::Zoom(f) => camera.zoom(f),
        Step::Pan(x, y) => camera.pan(x, y),
        _ => {}
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() || self.error.is_some() {
            return;
        }
        if let Err(e) = self.open(event_loop) {
            return self.fail(event_loop, e);
        }
        event_loop.set_control_flow(if self.options.frames.is_some() {
            ControlFlow::Poll
        } else {
            ControlFlow::Wait
        });
        self.redraw();
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let result = match event {
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::Resized(_) => {
                self.stale = true;
                self.redraw();
                Ok(())
            }
            WindowEvent::RedrawRequested => self.on_redraw(event_loop),
            // A held key's auto-repeats are ignored, and so are the presses winit makes up
            // for keys held while the window takes the focus: one press is one step (a
            // level change reruns the fragment passes; a late release must not add a level).
            WindowEvent::KeyboardInput { event, is_synthetic, .. }
                if event.state == ElementState::Pressed && !event.repeat && !is_synthetic =>
            {
                match event.logical_key.as_ref() {
                    Key::Named(NamedKey::Escape) => {
                        event_loop.exit();
                        Ok(())
                    }
                    Key::Character(c) => {
                        let k = match c {
                            "=" => '+',
                            "_" => '-',
                            "q" => {
                                event_loop.exit();
                                return;
                            }
                            other => other.chars().next().unwrap_or(' '),
                        };
                        let r = self.key(k);
                        self.redraw();
                        r
                    }
                    _ => Ok(()),
                }
            }
            WindowEvent::ModifiersChanged(m) => {
                self.mouse.modifiers = m.state();
                Ok(())
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let down = state == ElementState::Pressed;
                match button {
                    MouseButton::Left if self.mouse.modifiers.shift_key() || !down => {
                        self.mouse.pan = down && self.mouse.modifiers.shift_key();
                        self.mouse.orbit = false;
                    }
                    MouseButton::Left => self.mouse.orbit = true,
                    MouseButton::Right | MouseButton::Middle => self.mouse.pan = down,
                    _ => {}
                }
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => {
                let height = f64::from(self.window_size()[1].max(1));
                if let (Some(prev), Some(camera)) = (self.mouse.position, self.camera.as_mut()) {
                    let (dx, dy) = (position.x - prev.x, position.y - prev.y);
                    if self.mouse.orbit {
                        camera.orbit(-dx * 0.3f64.to_radians(), dy * 0.3f64.to_radians());
                        self.redraw();
                    } else if self.mouse.pan {
                        camera.pan(-dx / height, dy / height);
                        self.redraw();
                    }
                }
                self.mouse.position = Some(position);
                Ok(())
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let notches = match delta {
                    MouseScrollDelta::LineDelta(_, y) => f64::from(y),
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                if let Some(c) = self.camera.as_mut() {
                    c.zoom(0.9f64.powf(notches));
                }
                self.redraw();
                Ok(())
            }
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.fail(event_loop, e);
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        // Headless runs and scripts draw continuously until they are done.
        if self.options.frames.is_some() || !self.script_done() {
            self.redraw();
        }
    }
}

impl App {
    fn on_redraw(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        if self.frame()? {
            self.frames += 1;
            self.title();
        }
        if let Some(n) = self.options.frames
            && self.frames >= n
            && self.script_done()
        {
            event_loop.exit();
        }
        Ok(())
    }
}
