//! The Vulkan context: instance, the chosen device, one compute queue and its command pool.

use super::inject::{self, Step};
use super::pipeline_cache::PipelineCache;
use crate::{Error, Result};
use ash::vk;
use std::ffi::{c_void, CStr, CString};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Arc;

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";
const INSTALL_DRIVER: &str = "install a Vulkan driver: on Debian or Ubuntu, `apt-get install mesa-vulkan-drivers libvulkan1` gives the lavapipe CPU driver";

/// How to create a [`Context`].
#[derive(Clone, Debug, Default)]
pub struct ContextOptions {
    /// Case-insensitive substring of the device name to use (lavapipe is "llvmpipe").
    pub device_name: Option<String>,
    /// Enable the Khronos validation layer (with synchronisation validation) and count errors.
    pub validation: bool,
    /// The queue must also draw (rasterize), with dynamic rendering: for baking g-buffers.
    pub graphics: bool,
}

impl ContextOptions {
    /// Validation follows the `LOOKDEV_VALIDATION` environment variable (`1` turns it on).
    pub fn from_env(device_name: Option<String>) -> ContextOptions {
        let validation = std::env::var("LOOKDEV_VALIDATION").is_ok_and(|v| v == "1");
        ContextOptions { device_name, validation, graphics: false }
    }
}

/// What the renderer needs to know about the chosen device.
#[derive(Clone, Debug)]
pub struct DeviceInfo {
    pub name: String,
    pub device_type: vk::PhysicalDeviceType,
    /// Nanoseconds per timestamp tick, or None when the queue cannot write timestamps.
    pub timestamp_period_ns: Option<f64>,
    pub max_image_dimension_2d: u32,
    /// How many colour targets one draw may write.
    pub max_color_attachments: u32,
    pub max_image_array_layers: u32,
    pub subgroup_size: u32,
}

/// What presenting to a window needs of the context.
pub struct Presentation<'a> {
    /// Instance extensions the window system's surface needs.
    pub instance_extensions: &'a [*const std::ffi::c_char],
    /// Makes the window's surface once the instance exists; [`Surface`] then owns it.
    pub create_surface: &'a dyn Fn(&ash::Entry, &ash::Instance) -> Result<vk::SurfaceKHR>,
}

/// A window's Vulkan surface, destroyed when dropped. It holds on to its instance, so it may
/// outlive the context; the swapchain made on it must be destroyed first.
pub struct Surface {
    /// Keeps the instance until the surface is destroyed.
    _instance: Arc<Instance>,
    pub(crate) loader: ash::khr::surface::Instance,
    pub(crate) handle: vk::SurfaceKHR,
}

impl Surface {
    fn new(instance: &Arc<Instance>, handle: vk::SurfaceKHR) -> Surface {
        let loader = ash::khr::surface::Instance::new(&instance.entry, instance);
        Surface { _instance: instance.clone(), loader, handle }
    }
}

impl Drop for Surface {
    fn drop(&mut self) {
        unsafe { self.loader.destroy_surface(self.handle, None) };
    }
}

/// The validation message counter, shared with the debug callback.
#[derive(Default)]
pub struct ValidationCounter {
    errors: AtomicU32,
}

impl ValidationCounter {
    pub fn errors(&self) -> u32 {
        self.errors.load(Ordering::SeqCst)
    }
}

/// The Vulkan instance and, with validation on, the debug messenger that counts the layer's
/// errors. Destroyed when its last owner (the context's [`Shared`], a [`Surface`]) drops.
pub(crate) struct Instance {
    pub(crate) entry: ash::Entry,
    instance: ash::Instance,
    /// None until made, and without validation.
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    /// The messengers point at it, so it lives as long as the instance.
    _counter: Arc<ValidationCounter>,
}

impl std::ops::Deref for Instance {
    type Target = ash::Instance;
    fn deref(&self) -> &ash::Instance {
        &self.instance
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        unsafe {
            if let Some((loader, messenger)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
        inject::count_instance(-1);
    }
}

/// Everything that must outlive every buffer, image and pipeline; they hold an `Arc` to it, so the
/// device is destroyed only after the last of them (and the instance after the device).
pub(crate) struct Shared {
    pub(crate) instance: Arc<Instance>,
    pub(crate) physical_device: vk::PhysicalDevice,
    pub(crate) device: ash::Device,
    pub(crate) queue: vk::Queue,
    pub(crate) queue_family: u32,
    pub(crate) memory_properties: vk::PhysicalDeviceMemoryProperties,
    pub(crate) info: DeviceInfo,
    /// Null until made.
    command_pool: vk::CommandPool,
    /// What every pipeline is made through; None until made.
    pipeline_cache: Option<PipelineCache>,
    /// Serialises [`Context::run`]: the command pool and the queue must not be used from two
    /// threads at once.
    submission: std::sync::Mutex<()>,
    /// The device memory the buffers and images hold.
    pub(crate) memory: super::memory::MemoryUse,
}

impl Shared {
    /// The cache every pipeline is made through (null only while the context is being made).
    pub(crate) fn pipeline_cache(&self) -> vk::PipelineCache {
        self.pipeline_cache.as_ref().map_or(vk::PipelineCache::null(), |cache| cache.handle)
    }
}

impl Drop for Shared {
    fn drop(&mut self) {
        crate::timings::note(|| format!("device memory: peak {:.1} MiB", self.memory.peak() as f64 / (1 << 20) as f64));
        // Destroying a null handle does nothing, so a half-made context drops cleanly.
        unsafe {
            let _ = self.device.device_wait_idle();
            if let Some(cache) = &mut self.pipeline_cache {
                cache.save_and_destroy(&self.device);
            }
            self.device.destroy_command_pool(self.command_pool, None);
            self.device.destroy_device(None);
        }
    }
}

/// The one Vulkan context of a process: instance, device, queue and memory allocation.
#[derive(Clone)]
pub struct Context {
    pub(crate) shared: Arc<Shared>,
    counter: Arc<ValidationCounter>,
}

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    let message = unsafe { data.as_ref().and_then(|d| d.message_as_c_str()) }
        .map(|m| m.to_string_lossy().into_owned())
        .unwrap_or_default();
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        let counter = unsafe { &*(user as *const ValidationCounter) };
        counter.errors.fetch_add(1, Ordering::SeqCst);
        eprintln!("lookdev: validation error: {message}");
    } else {
        eprintln!("lookdev: validation warning: {message}");
    }
    vk::FALSE
}

fn rank(device_type: vk::PhysicalDeviceType) -> u32 {
    match device_type {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 3,
        _ => 4,
    }
}

fn device_name(props: &vk::PhysicalDeviceProperties) -> String {
    props.device_name_as_c_str().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
}

impl Context {
    /// Creates the context on the best device (discrete, then integrated, then CPU), or on the
    /// one whose name contains `options.device_name`.
    pub fn new(options: &ContextOptions) -> Result<Context> {
        Context::create(options, None).map(|(ctx, _)| ctx)
    }

    /// A context that can also present to a window: the instance has the surface's extensions,
    /// the device has the swapchain extension and dynamic rendering, and its queue can present
    /// to the surface, which is returned for the caller to own.
    pub fn with_surface(options: &ContextOptions, presentation: Presentation) -> Result<(Context, Surface)> {
        let (ctx, surface) = Context::create(options, Some(presentation))?;
        Ok((ctx, surface.expect("a surface was asked for")))
    }

    /// Each part is owned as soon as it is made (the instance, the surface, then the device in
    /// [`Shared`]), so a step that fails drops, and so destroys, the parts made before it.
    fn create(options: &ContextOptions, presentation: Option<Presentation>) -> Result<(Context, Option<Surface>)> {
        let _timing = crate::timings::phase("vulkan context");
        let entry = unsafe { ash::Entry::load() }
            .map_err(|e| Error::gpu(format!("no Vulkan loader found ({e}); {INSTALL_DRIVER}")))?;
        let counter = Arc::new(ValidationCounter::default());
        inject::watch(&counter);
        let extra = presentation.as_ref().map(|p| p.instance_extensions).unwrap_or_default();
        let instance = Arc::new(create_instance(&entry, options.validation, extra, &counter)?);
        let surface = match &presentation {
            Some(p) => {
                inject::check(Step::Surface)?;
                Some(Surface::new(&instance, (p.create_surface)(&entry, &instance)?))
            }
            None => None,
        };
        let shared = create_device(instance, options, surface.as_ref())?;
        inject::check(Step::ContextReady)?;
        Ok((Context { shared: Arc::new(shared), counter }, surface))
    }

    /// Validation errors reported so far (always 0 when validation is off).
    pub fn validation_errors(&self) -> u32 {
        self.counter.errors()
    }

    /// The counter itself, to read after the context and everything it made are dropped (errors
    /// about leaked objects arrive when the device is destroyed).
    pub fn validation_counter(&self) -> Arc<ValidationCounter> {
        self.counter.clone()
    }

    /// Holds the queue for a submission made outside [`Context::run`] (the viewer's frames).
    pub fn lock_queue(&self) -> std::sync::MutexGuard<'_, ()> {
        self.shared.submission.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    pub fn info(&self) -> &DeviceInfo {
        &self.shared.info
    }

    /// The device memory this context's buffers and images hold, now and at the most.
    pub fn memory(&self) -> &super::memory::MemoryUse {
        &self.shared.memory
    }

    /// Records commands with `record`, submits them and waits. A full memory barrier before
    /// makes the submission see everything earlier ones wrote; one after makes its writes
    /// visible to the host, for read-backs.
    pub fn run<T>(&self, record: impl FnOnce(vk::CommandBuffer) -> Result<T>) -> Result<T> {
        let shared = &*self.shared;
        let device = &shared.device;
        let _serialised = self.lock_queue();
        // From here on, Drop releases whatever has been created if a later step fails.
        let mut submission = Submission { shared, cmd: vk::CommandBuffer::null(), fence: vk::Fence::null() };
        unsafe {
            let alloc = vk::CommandBufferAllocateInfo::default()
                .command_pool(shared.command_pool)
                .level(vk::CommandBufferLevel::PRIMARY)
                .command_buffer_count(1);
            submission.cmd = device.allocate_command_buffers(&alloc)?[0];
            submission.fence = device.create_fence(&vk::FenceCreateInfo::default(), None)?;
            let (cmd, fence) = (submission.cmd, submission.fence);
            device.begin_command_buffer(
                cmd,
                &vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
            )?;
            full_barrier(device, cmd);
            let value = record(cmd)?;
            host_barrier(device, cmd);
            device.end_command_buffer(cmd)?;
            let cmds = [cmd];
            let submit = vk::SubmitInfo::default().command_buffers(&cmds);
            device.queue_submit(shared.queue, &[submit], fence)?;
            device.wait_for_fences(&[fence], true, u64::MAX)?;
            Ok(value)
        }
    }
}

/// The command buffer and fence of one [`Context::run`], released however it ends.
struct Submission<'a> {
    shared: &'a Shared,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
}

impl Drop for Submission<'_> {
    fn drop(&mut self) {
        let device = &self.shared.device;
        unsafe {
            device.destroy_fence(self.fence, None);
            if self.cmd != vk::CommandBuffer::null() {
                device.free_command_buffers(self.shared.command_pool, &[self.cmd]);
            }
        }
    }
}

/// A barrier between everything before and everything after, within one command buffer.
pub fn full_barrier(device: &ash::Device, cmd: vk::CommandBuffer) {
    let barrier = vk::MemoryBarrier::default()
        .src_access_mask(vk::AccessFlags::MEMORY_WRITE)
        .dst_access_mask(vk::AccessFlags::MEMORY_READ | vk::AccessFlags::MEMORY_WRITE);
    unsafe {
        device.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::ALL_COMMANDS,
            vk::PipelineStageFlags::ALL_COMMANDS,
            vk::DependencyFlags::empty(),
            &[barrier],
            &[],
            &[],
        );
    }
}

/// Makes everything written so far visible to host reads once the submission completes.
pub fn host_barrier(device: &ash::Device, cmd: vk::CommandBuffer) {
    let barrier = vk::MemoryBarrier::default()
        .src_access_mask(vk::AccessFlags::MEMORY_WRITE)
        .dst_access_mask(vk::AccessFlags::HOST_READ);
    unsafe {
        device.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::ALL_COMMANDS,
            vk::PipelineStageFlags::HOST,
            vk::DependencyFlags::empty(),
            &[barrier],
            &[],
            &[],
        );
    }
}

fn create_instance(
    entry: &ash::Entry,
    validation: bool,
    extra_extensions: &[*const std::ffi::c_char],
    counter: &Arc<ValidationCounter>,
) -> Result<Instance> {
    let app_name = CString::new("lookdev").expect("no interior NUL");
    let app_info = vk::ApplicationInfo::default()
        .application_name(&app_name)
        .application_version(vk::make_api_version(0, 0, 1, 0))
        .engine_name(&app_name)
        .api_version(vk::API_VERSION_1_3);

    let mut layers = Vec::new();
    let mut extensions = extra_extensions.to_vec();
    if validation {
        let available = unsafe { entry.enumerate_instance_layer_properties() }?;
        let found = available.iter().any(|l| l.layer_name_as_c_str().is_ok_and(|n| n == VALIDATION_LAYER));
        if !found {
            return Err(Error::gpu(
                "validation was requested (LOOKDEV_VALIDATION=1) but VK_LAYER_KHRONOS_validation is not installed: `apt-get install vulkan-validationlayers`",
            ));
        }
        layers.push(VALIDATION_LAYER.as_ptr());
        extensions.push(ash::ext::debug_utils::NAME.as_ptr());
        extensions.push(ash::ext::validation_features::NAME.as_ptr());
    }
    let enabled_features = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut validation_features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled_features);
    let mut instance_messenger = messenger_info(counter);
    let mut create_info = vk::InstanceCreateInfo::default()
        .application_info(&app_info)
        .enabled_layer_names(&layers)
        .enabled_extension_names(&extensions);
    if validation {
        // The messenger chained here also hears vkDestroyInstance, where the layer reports objects
        // left alive (a device, a surface), after the instance's own messenger is gone.
        create_info = create_info.push_next(&mut validation_features).push_next(&mut instance_messenger);
    }
    let instance = unsafe { entry.create_instance(&create_info, None) }.map_err(|e| match e {
        vk::Result::ERROR_INCOMPATIBLE_DRIVER => Error::gpu(format!("no Vulkan 1.3 driver found; {INSTALL_DRIVER}")),
        other => Error::gpu(format!("cannot create a Vulkan instance ({other}); {INSTALL_DRIVER}")),
    })?;
    inject::count_instance(1);
    // From here on, Drop releases whatever has been created if a later step fails.
    let mut instance = Instance { entry: entry.clone(), instance, debug: None, _counter: counter.clone() };
    if !validation {
        return Ok(instance);
    }
    inject::check(Step::DebugMessenger)?;
    let loader = ash::ext::debug_utils::Instance::new(entry, &instance);
    let messenger = unsafe { loader.create_debug_utils_messenger(&messenger_info(counter), None) }?;
    instance.debug = Some((loader, messenger));
    Ok(instance)
}

/// Errors and warnings from the validation layer, counted in `counter`.
fn messenger_info(counter: &Arc<ValidationCounter>) -> vk::DebugUtilsMessengerCreateInfoEXT<'static> {
    vk::DebugUtilsMessengerCreateInfoEXT::default()
        .message_severity(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING)
        .message_type(
            // Performance hints are left out: they flag lookdev's deliberate use of the GENERAL layout.
            vk::DebugUtilsMessageTypeFlagsEXT::GENERAL | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION,
        )
        .pfn_user_callback(Some(debug_callback))
        .user_data(Arc::as_ptr(counter) as *mut c_void)
}

/// Chooses the device and creates it, with its queue and command pool, for the caller's surface
/// if there is one.
fn create_device(instance: Arc<Instance>, options: &ContextOptions, surface: Option<&Surface>) -> Result<Shared> {
    let presents = |pd: vk::PhysicalDevice, family: u32| match surface {
        Some(surface) => {
            unsafe { surface.loader.get_physical_device_surface_support(pd, family, surface.handle) }.unwrap_or(false)
        }
        None => true,
    };
    let (physical_device, queue_family, info) =
        choose_physical_device(&instance, options, options.graphics || surface.is_some(), &presents)?;
    let priorities = [1.0f32];
    let queue_info =
        [vk::DeviceQueueCreateInfo::default().queue_family_index(queue_family).queue_priorities(&priorities)];
    // glslang's Vulkan 1.3 SPIR-V declares workgroup sizes with LocalSizeId, which needs maintenance4
    // (core in 1.3 and supported by every 1.3 driver). Drawing (a window, a bake) also needs
    // dynamic rendering.
    let draws = options.graphics || surface.is_some();
    let mut features13 = vk::PhysicalDeviceVulkan13Features::default().maintenance4(true).dynamic_rendering(draws);
    let extensions: Vec<*const std::ffi::c_char> =
        if surface.is_some() { vec![ash::khr::swapchain::NAME.as_ptr()] } else { Vec::new() };
    let device_info = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queue_info)
        .enabled_extension_names(&extensions)
        .push_next(&mut features13);
    inject::check(Step::Device)?;
    let device = unsafe { instance.create_device(physical_device, &device_info, None) }
        .map_err(|e| Error::gpu(format!("cannot create a Vulkan device on {} ({e})", info.name)))?;
    let queue = unsafe { device.get_device_queue(queue_family, 0) };
    let memory_properties = unsafe { instance.get_physical_device_memory_properties(physical_device) };
    // From here on, Drop releases whatever has been created if a later step fails.
    let mut shared = Shared {
        instance,
        physical_device,
        device,
        queue,
        queue_family,
        memory_properties,
        info,
        command_pool: vk::CommandPool::null(),
        pipeline_cache: None,
        submission: std::sync::Mutex::new(()),
        memory: Default::default(),
    };
    let pool_info = vk::CommandPoolCreateInfo::default()
        .queue_family_index(queue_family)
        .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
    inject::check(Step::CommandPool)?;
    shared.command_pool = unsafe { shared.device.create_command_pool(&pool_info, None) }?;
    let props = unsafe { shared.instance.get_physical_device_properties(physical_device) };
    shared.pipeline_cache = Some(PipelineCache::new(&shared.device, &props)?);
    Ok(shared)
}

/// The devices lookdev can use (Vulkan 1.3 with a compute queue; with `graphics`, one that also
/// draws and that `presents` accepts), best first.
fn candidates(
    instance: &ash::Instance,
    graphics: bool,
    presents: &dyn Fn(vk::PhysicalDevice, u32) -> bool,
) -> Result<Vec<(vk::PhysicalDevice, u32, DeviceInfo)>> {
    let devices = unsafe { instance.enumerate_physical_devices() }?;
    let mut candidates = Vec::new();
    for pd in devices {
        let props = unsafe { instance.get_physical_device_properties(pd) };
        if props.api_version < vk::API_VERSION_1_3 {
            continue;
        }
        let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
        let wanted =
            if graphics { vk::QueueFlags::COMPUTE | vk::QueueFlags::GRAPHICS } else { vk::QueueFlags::COMPUTE };
        let Some(family) =
            (0..families.len()).find(|&f| families[f].queue_flags.contains(wanted) && presents(pd, f as u32))
        else {
            continue;
        };
        let mut subgroup = vk::PhysicalDeviceSubgroupProperties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut subgroup);
        unsafe { instance.get_physical_device_properties2(pd, &mut props2) };
        let timestamps =
            families[family].timestamp_valid_bits > 0 && props.limits.timestamp_compute_and_graphics == vk::TRUE;
        let info = DeviceInfo {
            name: device_name(&props),
            device_type: props.device_type,
            timestamp_period_ns: timestamps.then_some(props.limits.timestamp_period as f64),
            max_image_dimension_2d: props.limits.max_image_dimension2_d,
            max_color_attachments: props.limits.max_color_attachments,
            max_image_array_layers: props.limits.max_image_array_layers,
            subgroup_size: subgroup.subgroup_size,
        };
        candidates.push((pd, family as u32, info));
    }
    candidates.sort_by_key(|c| rank(c.2.device_type));
    Ok(candidates)
}

fn choose_physical_device(
    instance: &ash::Instance,
    options: &ContextOptions,
    graphics: bool,
    presents: &dyn Fn(vk::PhysicalDevice, u32) -> bool,
) -> Result<(vk::PhysicalDevice, u32, DeviceInfo)> {
    let mut candidates = candidates(instance, graphics, presents)?;
    if candidates.is_empty() {
        return Err(Error::gpu(format!("no Vulkan 1.3 device with a compute queue was found; {INSTALL_DRIVER}")));
    }
    if let Some(wanted) = &options.device_name {
        let wanted_lower = wanted.to_lowercase();
        let names: Vec<String> = candidates.iter().map(|c| c.2.name.clone()).collect();
        return candidates.into_iter().find(|c| c.2.name.to_lowercase().contains(&wanted_lower)).ok_or_else(|| {
            Error::input(format!("--device {wanted}: no such device (available: {})", names.join(", ")))
        });
    }
    Ok(candidates.remove(0))
}

/// The names and kinds of the devices lookdev can use, best first (for `lookdev devices`).
pub fn list_devices() -> Result<Vec<(String, String)>> {
    let entry = unsafe { ash::Entry::load() }
        .map_err(|e| Error::gpu(format!("no Vulkan loader found ({e}); {INSTALL_DRIVER}")))?;
    let counter = Arc::new(ValidationCounter::default());
    let instance = create_instance(&entry, false, &[], &counter)?;
    let candidates = candidates(&instance, false, &|_, _| true);
    Ok(candidates?
        .into_iter()
        .map(|(_, _, info)| (info.name, format!("{:?}", info.device_type).to_lowercase().replace('_', " ")))
        .collect())
}
