//! The window and its frames. After each turn of the event loop the frame scheduler
//! ([`super::schedule`]) says what comes next: a frame, a slice of relighting with no frame, or
//! a wait. A frame takes one script step, runs the interface, carries out the actions it
//! produced, hands the renderer what changed, relights one band, and presents. Carrying out the
//! actions before relighting means an edit's first band is in the very frame that made it.
//! Everything happens when the event loop is about to wait, so that nothing depends on the
//! window system's redraw events, which only ask for a frame.

use super::action::{Action, Answer, Compare};
use super::environments::EnvironmentLibrary;
use super::gui::Gui;
use super::mask_overlay::MaskOverlay;
use super::presenter::Presenter;
use super::schedule::{FrameScheduler, Next, Situation};
use super::script::{ScriptRunner, Step};
use super::session::Session;
use super::thumbnails::{self, Thumbnails};
use super::ui::{FileDialog, FilePurpose, Frame, FrameFigures, Interface, Pending};
use super::view_image::Views;
use super::ViewOptions;
use crate::environment::EnvironmentRef;
use crate::gpu::context::{Presentation, ValidationCounter};
use crate::gpu::{Context, ContextOptions};
use crate::render::scene::{covered_object_ids, load_look_for, LookSource, Scene};
use crate::render::settings::{Overrides, Settings};
use crate::viewer_state::{Document, Edit, ObjectRef, Selection};
use crate::{Error, Result};
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::{Window, WindowId};

/// Opens the window and runs until it closes.
pub fn run(options: ViewOptions) -> Result<()> {
    // Everything that can be wrong with the input is found before a window opens.
    super::progressive::configure_budget()?;
    let inputs = Inputs::load(&options)?;
    let event_loop = EventLoop::new().map_err(super::no_display)?;
    let mut app = App { options, inputs: Some(inputs), running: None, outcome: Ok(()), validation: None };
    let ran = event_loop.run_app(&mut app);
    // The GPU objects go before the validation count is read: leaks are reported on destruction.
    app.running = None;
    ran.map_err(|e| Error::gpu(format!("the window system failed ({e})")))?;
    app.outcome?;
    match app.validation.map_or(0, |counter| counter.errors()) {
        0 => Ok(()),
        n => Err(Error::gpu(format!("Vulkan validation reported {n} error(s); see above"))),
    }
}

/// The files read and checked before the window opens.
struct Inputs {
    scene: Scene,
    document: Document,
}

impl Inputs {
    fn load(options: &ViewOptions) -> Result<Inputs> {
        let scene = Scene::load(&options.scene)?;
        // B's inputs are checked here too, so that a bad one is an error before a window opens.
        model_with(scene.settings.model, &options.compare_model, "--compare-model")?;
        if let Some(path) = &options.compare_look {
            load_look_for(path, &scene.gbuffer, &scene.gbuffer_name)?;
        }
        let path = match &options.scene.look {
            LookSource::File(path) => Some(path.clone()),
            _ => None,
        };
        // The look keeps the scene it is open on: saved, it reopens on the same g-buffer (or
        // the built-in one at the same size), whatever flags opened it.
        let mut look = scene.look.clone();
        look.gbuffer = scene.recorded.gbuffer.clone();
        let mut document = Document::new(look, path, scene.settings.clone());
        document.select(initial_selection(&document, &covered_object_ids(&scene.gbuffer)));
        Ok(Inputs { scene, document })
    }
}

/// The first shaded object with a stack of its own and its top layer, else the default stack.
fn initial_selection(document: &Document, covered: &[u32]) -> Selection {
    let look = document.look();
    let object = covered
        .iter()
        .find(|id| look.objects.iter().any(|o| o.id == Some(**id)))
        .map_or(ObjectRef::Default, |id| ObjectRef::Id(*id));
    let top = document.stack(object).map(|s| s.layers.len().saturating_sub(1));
    Selection { object: Some(object), layer: top }
}

struct App {
    options: ViewOptions,
    inputs: Option<Inputs>,
    running: Option<Running>,
    outcome: Result<()>,
    validation: Option<Arc<ValidationCounter>>,
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        let Some(inputs) = self.inputs.take() else { return };
        match Running::start(event_loop, &self.options, inputs) {
            Ok(running) => {
                self.validation = Some(running.ctx.validation_counter());
                self.running = Some(running);
            }
            Err(e) => {
                self.outcome = Err(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _window: WindowId, event: WindowEvent) {
        let Some(running) = &mut self.running else { return };
        match running.window_event(event) {
            Ok(true) => {}
            Ok(false) => event_loop.exit(),
            Err(e) => {
                self.outcome = Err(e);
                event_loop.exit();
            }
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let Some(running) = &mut self.running else { return };
        match running.turn() {
            Ok(flow) if !running.quit => event_loop.set_control_flow(flow),
            Ok(_) => event_loop.exit(),
            Err(e) => {
                self.outcome = Err(e);
                event_loop.exit();
            }
        }
    }
}

/// Where an action came from: the panels, whose failures are shown, or a script line, whose
/// failures stop the viewer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Origin {
    Interface,
    Script(usize),
}

/// The open window and everything drawn in it. Fields drop in order: the interface's GPU parts
/// before the context they were made from, the window after its surface.
struct Running {
    gui: Gui,
    presenter: Presenter,
    thumbnails: Thumbnails,
    environments: EnvironmentLibrary,
    session: Session,
    ctx: Context,
    window: Window,
    interface: Interface,
    script: Option<ScriptRunner>,
    queue: Vec<(Origin, Action)>,
    pending: Option<Pending>,
    /// The line and frame of the script's last key press, whose actions come a frame later.
    scripted_key: Option<(usize, u64)>,
    screenshots: Vec<PathBuf>,
    exit_after_spp: Option<u32>,
    final_screenshot: Option<PathBuf>,
    clock: FrameClock,
    scheduler: FrameScheduler,
    /// Whether a window event asked for a frame since the last one.
    frame_wanted: bool,
    title: String,
    next_repaint: Option<Instant>,
    quit: bool,
    views: Views,
    mask_overlay: MaskOverlay,
}

impl Running {
    fn start(event_loop: &ActiveEventLoop, options: &ViewOptions, inputs: Inputs) -> Result<Running> {
        let (width, height) = options.window_size;
        let attributes = Window::default_attributes()
            .with_title("lookdev")
            .with_inner_size(winit::dpi::LogicalSize::new(width, height));
        let window = event_loop.create_window(attributes).map_err(super::no_display)?;
        let handle_error = |e: raw_window_handle::HandleError| Error::gpu(format!("the window has no handle ({e})"));
        let display = window.display_handle().map_err(handle_error)?.as_raw();
        let window_handle = window.window_handle().map_err(handle_error)?.as_raw();
        let extensions = ash_window::enumerate_required_extensions(display)
            .map_err(|e| Error::gpu(format!("this window system cannot show Vulkan images ({e})")))?;
        let create_surface = |entry: &ash::Entry, instance: &ash::Instance| {
            unsafe { ash_window::create_surface(entry, instance, display, window_handle, None) }
                .map_err(|e| Error::gpu(format!("cannot draw into the window ({e})")))
        };
        let presentation = Presentation { instance_extensions: extensions, create_surface: &create_surface };
        let (ctx, surface) = Context::with_surface(&ContextOptions::from_env(options.device.clone()), presentation)?;
        let size = window.inner_size();
        let presenter = Presenter::new(&ctx, surface, size.width, size.height)?;
        let gui = Gui::new(&ctx, &window, &presenter)?;
        let thumbnails = Thumbnails::new(&ctx, thumbnails::cache_dir())?;
        let (environments, warning) = EnvironmentLibrary::load();
        inputs.scene.check_device(ctx.info())?;
        let Inputs { scene, document } = inputs;
        let mut session = Session::new(
            &ctx,
            scene.gbuffer,
            scene.gbuffer_name,
            document,
            scene.environment,
            options.scene.env_options,
            scene.recorded,
        )?;
        if let Some(path) = &options.compare_look {
            session.compare_look(path)?;
        } else if !options.compare_model.is_empty() {
            let model = model_with(session.document.settings().model, &options.compare_model, "--compare-model")?;
            session.compare_model(model)?;
        }
        if let Some(spp) = options.exit_after_spp {
            session.override_target(spp);
        }
        let mut running = Running {
            gui,
            presenter,
            thumbnails,
            environments,
            session,
            ctx,
            window,
            interface: Interface::with_zoom(options.zoom),
            script: options.script.clone().map(ScriptRunner::new),
            queue: Vec::new(),
            pending: None,
            scripted_key: None,
            screenshots: Vec::new(),
            exit_after_spp: options.exit_after_spp,
            final_screenshot: options.screenshot.clone(),
            clock: FrameClock::default(),
            scheduler: FrameScheduler::new(super::progressive::frame_budget()),
            frame_wanted: true,
            title: String::new(),
            next_repaint: None,
            quit: false,
            views: Views::default(),
            mask_overlay: MaskOverlay::default(),
        };
        if let Some(warning) = warning {
            crate::warn(&warning);
            running.interface.tell(warning, true);
        }
        running.update_title();
        Ok(running)
    }

    /// Handles one window event. Returns false when the viewer should close.
    fn window_event(&mut self, event: WindowEvent) -> Result<bool> {
        match &event {
            WindowEvent::RedrawRequested => {
                self.frame_wanted = true;
                return Ok(!self.quit);
            }
            WindowEvent::CloseRequested => self.queue.push((Origin::Interface, Action::Quit)),
            WindowEvent::Resized(size) => {
                self.presenter.resize(size.width, size.height);
                self.frame_wanted = true;
            }
            _ => {}
        }
        if self.gui.on_event(&self.window, &event) {
            self.frame_wanted = true;
            self.scheduler.input(Instant::now());
        }
        Ok(true)
    }

    /// One turn of the event loop, before it waits: a frame, a slice of relighting or nothing,
    /// as the frame scheduler decides. Returns how the loop should wait.
    fn turn(&mut self) -> Result<ControlFlow> {
        let situation = self.situation();
        match self.scheduler.next(&situation) {
            Next::Draw { relight } => {
                self.frame_wanted = false;
                self.redraw(relight)?;
                Ok(ControlFlow::Poll)
            }
            Next::Relight(slice) => {
                self.clock.slices += 1;
                let end = Instant::now() + slice;
                while let Some(left) = end.checked_duration_since(Instant::now()).filter(|d| !d.is_zero()) {
                    if !self.session.step(left)? {
                        break;
                    }
                }
                Ok(ControlFlow::Poll)
            }
            Next::Wait(Some(at)) => Ok(ControlFlow::WaitUntil(at)),
            Next::Wait(None) => Ok(ControlFlow::Wait),
        }
    }

    /// What the frame scheduler needs to know now.
    fn situation(&self) -> Situation {
        let samples = self.session.samples();
        let target = self.session.target();
        let script_ready = self.script.as_ref().is_some_and(|runner| runner.ready(self.shown_samples(), target));
        let exiting = self.exit_after_spp.is_some_and(|spp| {
            self.script.as_ref().is_none_or(|s| s.finished()) && (samples >= spp || self.session.converged())
        });
        Situation {
            now: Instant::now(),
            rendering: !self.session.converged(),
            samples,
            target,
            needs_frame: self.frame_wanted
                || script_ready
                || exiting
                || !self.queue.is_empty()
                || !self.screenshots.is_empty(),
            repaint_at: self.next_repaint,
        }
    }

    /// The samples a script's wait counts: under a noise threshold, a wait ends once every
    /// pixel has stopped.
    fn shown_samples(&self) -> u32 {
        if self.session.converged() {
            u32::MAX
        } else {
            self.session.samples()
        }
    }

    /// Draws a frame, relighting for `relight` in it.
    fn redraw(&mut self, relight: Duration) -> Result<()> {
        let started = Instant::now();
        let finishing = self.headless_done();
        // Before the frame's actions too, so that the first one finds the look's snapshots.
        self.follow_look_file();
        if !finishing {
            self.script_step()?;
        }
        let view_texture = self.gui.view_texture(0, self.session.display_image())?;
        let compare_texture = match self.session.compare_image() {
            Some(image) => Some(self.gui.view_texture(1, image)?),
            None => {
                self.gui.release_view_texture(1);
                None
            }
        };
        // B's textures now name only a live image (or none): a replaced B can go.
        self.session.drop_retired()?;
        self.views.update(&mut self.session, &self.gui.egui)?;
        self.mask_overlay.update(&self.session, &self.gui.egui);
        let mut actions = Vec::new();
        let frame = Frame {
            session: &self.session,
            view_texture,
            compare_texture,
            pending: self.pending.as_ref(),
            figures: FrameFigures { frame: self.clock.recent_mean() },
            views: &self.views,
            mask_overlay: self.mask_overlay.texture(),
            environments: &self.environments,
        };
        let output =
            self.gui.run(&self.window, |ui| self.interface.show(ui, &frame, &mut self.thumbnails, &mut actions));
        self.next_repaint = Gui::repaint_delay(&output).map(|delay| Instant::now() + delay);
        self.queue.extend(actions.into_iter().map(|action| (Origin::Interface, action)));
        for (origin, action) in std::mem::take(&mut self.queue) {
            self.perform(origin, action)?;
        }
        self.follow_look_file();
        if let Err(e) = self.session.sync() {
            // Keep the renderer and the document in agreement: take the change back.
            self.session.document.undo();
            self.session.sync()?;
            self.interface.tell(format!("{e}; the change was undone"), true);
        }
        if !finishing && !relight.is_zero() {
            self.session.step(relight)?;
        }
        self.session.prepare_display()?;
        self.session.refresh_delta_e()?;
        self.update_title();
        let capture = finishing || !self.screenshots.is_empty();
        let captured = self.gui.draw(&mut self.presenter, output, capture)?;
        if capture {
            self.save_screenshots(captured, finishing)?;
        }
        self.clock.record(started.elapsed(), !self.session.converged(), self.session.samples());
        self.scheduler.drawn(Instant::now(), self.session.samples(), started.elapsed());
        Ok(())
    }

    /// With `--exit-after-spp`: the script (if any) is done and the image has its samples.
    fn headless_done(&self) -> bool {
        let Some(spp) = self.exit_after_spp else { return false };
        self.script.as_ref().is_none_or(|s| s.finished())
            && self.pending.is_none()
            && self.queue.is_empty()
            && (self.session.samples() >= spp || self.session.converged())
            && self.clock.frames >= 3
    }

    /// Queues the script's next action, unless it is waiting for samples.
    fn script_step(&mut self) -> Result<()> {
        let samples = self.shown_samples();
        let Some(runner) = &mut self.script else { return Ok(()) };
        // A key pressed last frame acts in this one's interface: its question, if it raises
        // one, comes before the script's next line, which may answer it.
        if self.scripted_key.is_some_and(|(_, frame)| self.clock.frames <= frame + 1) {
            return Ok(());
        }
        let capped = self.session.target_override().is_some();
        let Some((line, step)) = runner.next(samples, self.session.target(), capped)? else {
            return Ok(());
        };
        let action = match step {
            Step::Do(action) => action,
            Step::Layer(change) => {
                let (object, layer) = selected_layer(&self.session.document).map_err(|e| runner.error_at(line, e))?;
                Action::Edit(change.edit(object, layer))
            }
            Step::WaitSpp(_) => return Ok(()),
        };
        self.queue.push((Origin::Script(line), action));
        Ok(())
    }

    /// Carries out an action. A failure from the panels is shown in the status bar; one from a
    /// script line stops the viewer, naming the line.
    fn perform(&mut self, origin: Origin, action: Action) -> Result<()> {
        let scripted_pick =
            matches!((origin, &action), (Origin::Script(_), Action::Pick { .. } | Action::ShowInspection));
        if let Origin::Script(_) = origin {
            self.scheduler.input(Instant::now());
        }
        if let (Origin::Script(line), Action::Key(..)) = (origin, &action) {
            self.scripted_key = Some((line, self.clock.frames));
        }
        let asked_before = self.pending.is_some();
        let outcome = self.try_perform(action);
        if let (false, true, Some(runner)) = (asked_before, self.pending.is_some(), &self.script) {
            // A question the script raised, by a line or by a key it pressed (which the
            // interface answers within the next frames), must be answered by the script.
            match (origin, self.scripted_key) {
                (Origin::Script(line), _) => runner.check_answerable(line)?,
                (Origin::Interface, Some((line, frame))) if self.clock.frames <= frame + 2 => {
                    runner.check_answerable(line)?
                }
                _ => {}
            }
        }
        if let (true, Ok(_), Some(pixel)) = (scripted_pick, &outcome, &self.session.inspection) {
            println!("lookdev: {pixel}");
        }
        match (outcome, origin) {
            (Ok(Some(note)), _) => self.interface.tell(note, false),
            (Ok(None), _) => {}
            (Err(e), Origin::Interface) => self.interface.tell(e.to_string(), true),
            (Err(e), Origin::Script(line)) => {
                let runner = self.script.as_ref().expect("a script line came from the script");
                return Err(runner.error_at(line, e));
            }
        }
        Ok(())
    }

    fn try_perform(&mut self, action: Action) -> Result<Option<String>> {
        let document = &mut self.session.document;
        match action {
            Action::Edit(edit) => document.apply(edit).map_err(Error::input)?,
            Action::Drag(edit) => document.apply_merging(edit).map_err(Error::input)?,
            Action::EndGesture => document.end_gesture(),
            Action::Undo => {
                if !document.undo() {
                    return Ok(Some("nothing to undo".into()));
                }
            }
            Action::Redo => {
                if !document.redo() {
                    return Ok(Some("nothing to redo".into()));
                }
            }
            Action::Select(selection) => {
                if let Some(object) = selection.object {
                    self.session.check_object(object)?;
                }
                self.session.document.select(selection);
            }
            Action::AddPresetLayer(preset) => {
                let object = document.selection().object.unwrap_or(ObjectRef::Default);
                document.apply(Edit::AddLayer { object, preset: preset.clone() }).map_err(Error::input)?;
                let top = document.stack(object).map(|s| s.layers.len() - 1);
                document.select(Selection { object: Some(object), layer: top });
                return Ok(Some(format!("added {preset} on top of {object}")));
            }
            Action::SetShadowCatcher(catcher) => {
                let object = document.selection().object.unwrap_or(ObjectRef::Default);
                document.apply(Edit::SetShadowCatcher { object, catcher }).map_err(Error::input)?;
                let what = if catcher { "catches shadows" } else { "no longer catches shadows" };
                return Ok(Some(format!("{object} {what}")));
            }
            Action::SetMask(mask) => {
                if let Some(name) = mask.as_ref().filter(|m| !self.session.masks().contains(m)) {
                    let has = self.session.masks().join(", ");
                    return Err(Error::input(format!("the g-buffer has no mask '{name}' (it has: {has})")));
                }
                let document = &mut self.session.document;
                let (object, layer) = selected_layer(document)?;
                document.apply(Edit::SetMask { object, layer, mask }).map_err(Error::input)?;
            }
            Action::SetMap { param, map } => {
                if let Some(name) = &map {
                    crate::material::stack::check_binding(
                        param,
                        name,
                        &self.session.gbuffer,
                        &self.session.gbuffer_name,
                    )
                    .map_err(Error::input)?;
                }
                let document = &mut self.session.document;
                let (object, layer) = selected_layer(document)?;
                document.apply(Edit::SetMap { object, layer, param, map }).map_err(Error::input)?;
            }
            Action::Pick { x, y } => {
                let pixel = self.session.inspect(x, y)?;
                if pixel.coverage > 0.0 {
                    self.session.document.select_object(ObjectRef::Id(pixel.object_id));
                }
            }
            Action::ShowInspection => {
                if self.session.inspection.is_none() {
                    return Err(Error::input("no pixel is picked: 'pick X Y' first"));
                }
            }
            Action::OpenEnvironment(path) => {
                self.session.load_environment(path.as_ref())?;
                self.session.document.apply(Edit::SetEnvironment(path.clone())).map_err(Error::input)?;
                if let Some(reference) = &path {
                    if let Err(e) = self.environments.opened(reference) {
                        crate::warn(e.to_string());
                        self.interface.tell(e.to_string(), true);
                    }
                    self.interface.refresh_environments();
                }
            }
            Action::OpenLook(path) => {
                if document.is_dirty() {
                    self.pending = Some(Pending::Open(path));
                } else {
                    return self.open_look(&path);
                }
            }
            Action::SaveLook(path) => {
                let written = document.save(path.as_deref())?;
                return Ok(Some(format!("saved {}", written.display())));
            }
            Action::SaveLayerAsPreset { name, description, tags, force } => {
                let (object, layer) = selected_layer(document)?;
                let written = document.save_layer_as_preset(object, layer, &name, &description, &tags, force)?;
                let bound = document.stack(object).map_or(0, |s| s.layers[layer].maps.len());
                self.interface.refresh_library();
                let dropped = match bound {
                    0 => String::new(),
                    n => format!(" (constants only: its {n} map binding(s) stay in the look)"),
                };
                return Ok(Some(format!("saved preset {name} to {}{dropped}", written.display())));
            }
            Action::SaveImage(path) => {
                let spp = self.session.save_image(&path)?;
                return Ok(Some(format!("saved {} ({spp} spp)", path.display())));
            }
            Action::Screenshot(path) => self.screenshots.push(path),
            Action::Quit => {
                if document.is_dirty() {
                    self.pending = Some(Pending::Quit);
                } else {
                    self.quit = true;
                }
            }
            Action::Compare(compare) => return self.compare(compare),
            Action::Divider(at) => {
                if !(at.is_finite() && (0.0..=1.0).contains(&at)) {
                    return Err(Error::input(format!("divider {at} is outside [0, 1]")));
                }
                self.session.divider = at;
            }
            Action::Key(key, modifiers) => self.gui.press_key(key, modifiers),
            Action::Zoom(scale) => self.interface.viewport.zoom_to(scale),
            Action::View(choice) => return self.views.choose(&mut self.session, choice).map(Some),
            Action::Clipping(on) => return Ok(Some(self.views.set_clipping(on))),
            Action::Probe { x, y } => {
                let line = self.views.probe(&mut self.session, x, y)?;
                println!("lookdev: {line}");
                return Ok(Some(line));
            }
            Action::Snapshot(name) => {
                let name = self.session.take_snapshot(name.as_deref())?;
                let spp = self.session.snapshots.get(&name)?.spp;
                return Ok(Some(format!("snapshot {name} taken ({spp} spp)")));
            }
            Action::RestoreSnapshot(name) => {
                let edit = self.session.restore_edit(&name)?;
                self.session.document.apply(edit).map_err(Error::input)?;
                return Ok(Some(format!("restored the look of snapshot {name} (undo brings back the previous one)")));
            }
            Action::DeleteSnapshot(name) => {
                self.session.delete_snapshot(&name)?;
                return Ok(Some(format!("deleted snapshot {name}")));
            }
            Action::Visibility(on) => {
                if !self.session.has_visibility() {
                    return Err(Error::input("the g-buffer has no visibility to switch"));
                }
                self.session.set_visibility(on)?;
                let state = if on {
                    "on: shadows and occlusion"
                } else {
                    "off: every direction above the horizon sees the sky"
                };
                return Ok(Some(format!("visibility {state}")));
            }
            Action::Denoise(on) => {
                self.session.set_denoise(on);
                let state = if on { "on: the view is denoised; saved images are not" } else { "off" };
                return Ok(Some(format!("display filter {state}")));
            }
            Action::StepEnvironment(by) => {
                // A map that does not load is passed over (and named), so one bad file in a
                // folder does not stop the stepping there.
                let mut at = EnvironmentRef::or_default(self.session.document.settings().environment.as_ref());
                let mut skipped = Vec::new();
                for _ in 0..self.environments.listing().order().len() {
                    let next = self.environments.step(&at, by).expect("the library lists the built-ins");
                    match self.session.load_environment(Some(&next)) {
                        Ok(()) => {
                            self.session
                                .document
                                .apply(Edit::SetEnvironment(Some(next.clone())))
                                .map_err(Error::input)?;
                            let mut note = format!("environment: {}", next.label());
                            if !skipped.is_empty() {
                                note.push_str(&format!(" (passed over: {})", skipped.join("; ")));
                            }
                            return Ok(Some(note));
                        }
                        Err(e) => skipped.push(e.to_string()),
                    }
                    at = next;
                }
                return Err(Error::input(format!("no environment loads: {}", skipped.join("; "))));
            }
            Action::AddEnvironmentFolder(folder) => {
                let added = self.environments.add_folder(&folder)?;
                self.interface.refresh_environments();
                let verb = if added { "added" } else { "already in the library:" };
                return Ok(Some(format!("{verb} {}", folder.display())));
            }
            Action::RemoveEnvironmentFolder(folder) => {
                self.environments.remove_folder(&folder)?;
                self.interface.refresh_environments();
            }
            Action::ShowEnvironments => self.interface.show_environments(),
            Action::Solo(on) => {
                let (object, layer) = selected_layer(&self.session.document)?;
                let stack = self.session.document.stack(object).expect("selected_layer() checked it");
                let (id, label) = (stack.layers[layer].id, super::session::layer_label(&stack.layers[layer]));
                self.session.solo = on.then_some(id);
                self.session.sync()?;
                let state = if on { format!("solo: {label} alone in {object}") } else { "solo off".to_string() };
                return Ok(Some(state));
            }
            Action::MaskOverlay(on) => return Ok(Some(self.mask_overlay.set(on))),
            Action::Answer(answer) => {
                let pending = self.pending.take().ok_or_else(|| Error::input("there is no question to answer"))?;
                match answer {
                    Answer::Cancel => {}
                    Answer::Discard => return self.proceed(pending),
                    Answer::Save if document.path().is_none() => {
                        self.pending = Some(pending);
                        self.interface.file_dialog = Some(FileDialog::new(FilePurpose::SaveLook));
                        return Err(Error::input("the look has no file yet: choose where to save it"));
                    }
                    Answer::Save => {
                        document.save(None)?;
                        return self.proceed(pending);
                    }
                }
            }
        }
        Ok(None)
    }

    /// Starts, changes, swaps or ends the A/B split.
    fn compare(&mut self, compare: Compare) -> Result<Option<String>> {
        match compare {
            Compare::Model(keys) => {
                let model = model_with(self.session.document.settings().model, &keys, "compare model")?;
                self.session.compare_model(model)?;
            }
            Compare::Look(path) => self.session.compare_look(&path)?,
            Compare::Off => self.session.compare_off(),
            Compare::Snapshot(name, view) => self.session.compare_snapshot(&name, view)?,
            Compare::Swap => match self.session.compare_subject().map(|s| s.look_path().map(Path::to_path_buf)) {
                None => return Err(Error::input("swap: nothing is being compared")),
                Some(None) => self.session.swap_models()?,
                Some(Some(b_path)) => {
                    // A opens B's file and B shows A's: A's edits must be saved first, or be lost.
                    let document = &self.session.document;
                    let a_path = match document.path() {
                        Some(path) if !document.is_dirty() => path.to_path_buf(),
                        Some(_) => return Err(Error::input("swap: the look has unsaved edits; save them first")),
                        None => return Err(Error::input("swap: the look has no file; save it first")),
                    };
                    self.open_look(&b_path)?;
                    self.session.compare_look(&a_path)?;
                }
            },
        }
        Ok(self.session.compare_labels().map(|(a, b)| format!("comparing {a} | {b}")))
    }

    /// Does what the unsaved-edits question held back.
    fn proceed(&mut self, pending: Pending) -> Result<Option<String>> {
        match pending {
            Pending::Quit => {
                self.quit = true;
                Ok(None)
            }
            Pending::Open(path) => self.open_look(&path),
        }
    }

    fn open_look(&mut self, path: &Path) -> Result<Option<String>> {
        let (mut look, _, warnings) = load_look_for(path, &self.session.gbuffer, &self.session.gbuffer_name)?;
        let mut settings = Settings::resolve(&look, &Overrides::default())?;
        // It is shown on this scene, and saved with it.
        look.gbuffer = self.session.recorded().gbuffer.clone();
        // Adaptive sampling is the viewer's (`--noise-threshold`), not the look's.
        settings.noise = self.session.document.settings().noise;
        let mut document = Document::new(look, Some(path.to_path_buf()), settings);
        document.select(initial_selection(&document, self.session.objects()));
        self.session.replace_document(document)?;
        warnings.into_iter().for_each(crate::warn);
        Ok(Some(format!("opened {}", path.display())))
    }

    fn save_screenshots(&mut self, captured: Option<image::RgbaImage>, finishing: bool) -> Result<()> {
        let Some(image) = captured else {
            if !self.presenter.capturable() {
                return Err(Error::gpu(format!(
                    "{} cannot copy the window's images, so no screenshot can be taken",
                    self.session.device_name()
                )));
            }
            return Ok(()); // the frame was skipped (resized, minimised): try the next one
        };
        let mut paths = std::mem::take(&mut self.screenshots);
        if finishing {
            paths.extend(self.final_screenshot.take());
        }
        for path in &paths {
            crate::render::output::write_png_image(path, &image)?;
            let mut placement = self.interface.placement.map_or(String::new(), |p| {
                format!("; the image is at {},{} size {}x{} scale {}", p.x, p.y, p.width, p.height, p.scale)
            });
            if let (Some(column), Some((a, b))) = (self.session.split_column(), self.session.compare_labels()) {
                placement += &format!("; split at image column {column} ({a} | {b})");
            }
            placement += &self.snapshot_report();
            if let Some(showing) = self.interface.showing(&self.session) {
                placement += &format!("; {showing}");
            }
            if let Some(region) = self.session.restarted_region() {
                placement += &format!("; {}", super::ui::region_status(region));
            }
            if let Some((active, noise)) = self.session.adaptive() {
                placement += &format!("; adaptive {}: {active} px sampling", noise.threshold);
            }
            println!(
                "lookdev: screenshot {} ({}x{} window, {} spp{placement})",
                path.display(),
                image.width(),
                image.height(),
                self.session.samples()
            );
        }
        if finishing {
            eprintln!("lookdev: {}", self.report());
            self.quit = true;
        }
        Ok(())
    }

    /// Lists the snapshots of the look's file, when that file changed (see
    /// [`Session::follow_look_file`]): says which there are and which could not be read.
    fn follow_look_file(&mut self) {
        let Some(warnings) = self.session.follow_look_file() else { return };
        let snapshots = &self.session.snapshots;
        if let (Some(file), false) = (snapshots.look_file(), snapshots.list.is_empty()) {
            let list: Vec<String> =
                snapshots.list.iter().map(|s| format!("{} ({} spp, {})", s.name, s.spp, s.taken)).collect();
            let name = file.file_name().map_or(file.display().to_string(), |n| n.to_string_lossy().into_owned());
            println!("lookdev: snapshots of {name}: {}", list.join(", "));
        }
        for warning in warnings {
            crate::warn(&warning);
            self.interface.tell(warning, true);
        }
    }

    /// What a screenshot shows of a snapshot beside the live image: where the side-by-side
    /// snapshot is, and the ΔE figures.
    fn snapshot_report(&self) -> String {
        let Some(shown) = self.session.snapshot_compare() else { return String::new() };
        let mut report = String::new();
        if let Some((x, y)) = self.interface.placement.and_then(|p| p.second) {
            report += &format!("; snapshot {} is at {x},{y}", shown.name);
        }
        if let (Some(delta), Some(samples)) = (&shown.delta, self.session.delta_e_samples()) {
            report += &format!(
                "; ΔE2000 live ({samples} spp) vs snapshot {}: mean {:.4} max {:.4}",
                shown.name, delta.mean, delta.max
            );
        }
        report
    }

    /// The figures a headless run ends with.
    fn report(&self) -> String {
        let session = &self.session;
        let first =
            session.first_pass_after_change.map_or("n/a".to_string(), |d| format!("{:.0} ms", d.as_secs_f64() * 1e3));
        let preview = session.progressive.preview.map_or("n/a".to_string(), |(d, block)| {
            format!("{:.0} ms ({block}x{block} blocks)", d.as_secs_f64() * 1e3)
        });
        format!(
            "viewer: {}x{} on {}: {} spp; frame time while rendering {}; {} frames drawn, {} relighting slices between them; preview after the last change {preview}; first full pass after it {first}; {:.1} M samples/s",
            session.width(),
            session.height(),
            session.device_name(),
            session.samples(),
            self.clock.rendering_summary(),
            self.clock.frames,
            self.clock.slices,
            session.progressive.samples_per_second_with(session.compare_progressive()) / 1e6
        )
    }

    fn update_title(&mut self) {
        let document = &self.session.document;
        let name = document.path().and_then(|p| p.file_name()).map_or("untitled look".into(), |n| n.to_string_lossy());
        let title = format!("{name}{} — lookdev", if document.is_dirty() { " •" } else { "" });
        if title != self.title {
            self.window.set_title(&title);
            self.title = title;
        }
    }
}

/// `model` with `KEY=VALUE` changes; errors name `flag`.
fn model_with(
    mut model: crate::shading::model::Model,
    keys: &[String],
    flag: &str,
) -> Result<crate::shading::model::Model> {
    for key in keys {
        model.set_from_flag(flag, key).map_err(Error::input)?;
    }
    Ok(model)
}

/// The layer the selection points at.
fn selected_layer(document: &Document) -> Result<(ObjectRef, usize)> {
    let selection = document.selection();
    match (selection.object, selection.layer) {
        (Some(object), Some(layer)) => Ok((object, layer)),
        _ => Err(Error::input("no layer is selected")),
    }
}

/// Frame times: a recent mean for the status bar, and every frame spent rendering for the
/// report, which also counts the relighting slices run without a frame.
#[derive(Default)]
struct FrameClock {
    frames: u64,
    slices: u64,
    recent: Vec<Duration>,
    /// Each frame drawn while rendering: its time and the samples it showed.
    rendering: Vec<(Duration, u32)>,
}

impl FrameClock {
    /// Frames in the recent mean.
    const RECENT: usize = 30;

    fn record(&mut self, time: Duration, rendering: bool, samples: u32) {
        self.frames += 1;
        if self.recent.len() == Self::RECENT {
            self.recent.remove(0);
        }
        self.recent.push(time);
        // The first frames build pipelines and fonts; they are not what an artist waits for.
        if rendering && self.frames > 3 {
            self.rendering.push((time, samples));
        }
    }

    fn recent_mean(&self) -> Duration {
        if self.recent.is_empty() {
            Duration::ZERO
        } else {
            self.recent.iter().sum::<Duration>() / self.recent.len() as u32
        }
    }

    /// "median 31 ms, 95th percentile 40 ms, longest 52 ms over 120 frames, showing 4 spp
    /// (median)"; 0 spp is a preview, or a first pass not yet done.
    fn rendering_summary(&self) -> String {
        if self.rendering.is_empty() {
            return "n/a".into();
        }
        let mut times: Vec<f64> = self.rendering.iter().map(|(d, _)| d.as_secs_f64() * 1e3).collect();
        times.sort_by(f64::total_cmp);
        let at = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize];
        let mut shown: Vec<u32> = self.rendering.iter().map(|&(_, samples)| samples).collect();
        shown.sort_unstable();
        format!(
            "median {:.1} ms, 95th percentile {:.1} ms, longest {:.1} ms over {} frames, showing {} spp (median)",
            at(0.5),
            at(0.95),
            at(1.0),
            times.len(),
            shown[shown.len() / 2]
        )
    }
}
