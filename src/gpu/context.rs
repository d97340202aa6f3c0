//! Instance, device selection and the shared device state every GPU resource holds on to.

use std::ffi::{c_void, CStr};
use std::mem::ManuallyDrop;
use std::sync::{Arc, Mutex, MutexGuard};

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use super::error::{GpuError, GpuResult, VkContext};

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";
const API_VERSION: u32 = vk::API_VERSION_1_2;

/// Whether the Khronos validation layer is loaded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Validation {
    Off,
    /// On when the layer is installed, silently off otherwise.
    IfInstalled,
    /// On, and an error when the layer is missing (CI uses this so that a missing layer
    /// cannot hide validation errors).
    Required,
}

impl Validation {
    /// Debug builds validate; release builds validate when `OCULAR_VALIDATION=1`, and demand
    /// the layer when `OCULAR_VALIDATION=required`.
    pub fn from_build_and_env() -> Self {
        match std::env::var("OCULAR_VALIDATION").as_deref() {
            Ok("required") => Validation::Required,
            Ok("1") | Ok("on") => Validation::IfInstalled,
            Ok("0") | Ok("off") => Validation::Off,
            _ if cfg!(debug_assertions) => Validation::IfInstalled,
            _ => Validation::Off,
        }
    }

    /// Tests always validate; `OCULAR_VALIDATION=required` (set by ci/test.sh) makes a missing
    /// layer an error instead of a silent pass.
    pub fn for_tests() -> Self {
        match std::env::var("OCULAR_VALIDATION").as_deref() {
            Ok("required") => Validation::Required,
            _ => Validation::IfInstalled,
        }
    }
}

#[derive(Clone, Debug)]
pub struct ContextOptions {
    /// Device index (as `ocular devices` lists them) or a case-insensitive name substring.
    pub device: Option<String>,
    pub validation: Validation,
}

impl Default for ContextOptions {
    fn default() -> Self {
        ContextOptions {
            device: None,
            validation: Validation::from_build_and_env(),
        }
    }
}

impl ContextOptions {
    /// Options for tests: validation on, device from `OCULAR_DEVICE` (ci/test.sh pins lavapipe
    /// through the loader instead, so that a developer's real GPU is used when present).
    pub fn for_tests() -> Self {
        ContextOptions {
            device: std::env::var("OCULAR_DEVICE")
                .ok()
                .filter(|s| !s.is_empty()),
            validation: Validation::for_tests(),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum DeviceKind {
    Discrete,
    Integrated,
    Virtual,
    Cpu,
    Other,
}

impl DeviceKind {
    fn from_vk(t: vk::PhysicalDeviceType) -> Self {
        match t {
            vk::PhysicalDeviceType::DISCRETE_GPU => DeviceKind::Discrete,
            vk::PhysicalDeviceType::INTEGRATED_GPU => DeviceKind::Integrated,
            vk::PhysicalDeviceType::VIRTUAL_GPU => DeviceKind::Virtual,
            vk::PhysicalDeviceType::CPU => DeviceKind::Cpu,
            _ => DeviceKind::Other,
        }
    }

    /// Lower is preferred: a discrete GPU first, a CPU implementation last.
    fn preference(self) -> u8 {
        match self {
            DeviceKind::Discrete => 0,
            DeviceKind::Integrated => 1,
            DeviceKind::Virtual => 2,
            DeviceKind::Other => 3,
            DeviceKind::Cpu => 4,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            DeviceKind::Discrete => "discrete GPU",
            DeviceKind::Integrated => "integrated GPU",
            DeviceKind::Virtual => "virtual GPU",
            DeviceKind::Cpu => "CPU",
            DeviceKind::Other => "other",
        }
    }
}

/// What `ocular devices` shows about one physical device.
#[derive(Clone, Debug, serde::Serialize)]
pub struct DeviceInfo {
    pub index: usize,
    pub name: String,
    pub kind: DeviceKind,
    pub vulkan_version: String,
    pub driver: String,
    pub device_local_mib: u64,
    /// The largest single memory allocation the device allows (`maxMemoryAllocationSize`).
    pub max_allocation_mib: u64,
    /// Why ocular cannot use it, if it cannot.
    pub unsuitable: Option<String>,
}

/// Collects validation-layer messages so that the call that caused them can fail. Shared with
/// whoever asks (tests keep it past the context's destruction to catch leak reports).
#[derive(Default, Debug)]
pub struct ValidationLog {
    messages: Mutex<Vec<String>>,
}

impl ValidationLog {
    pub fn take(&self) -> Vec<String> {
        std::mem::take(&mut *self.lock())
    }

    pub fn is_empty(&self) -> bool {
        self.lock().is_empty()
    }

    fn lock(&self) -> MutexGuard<'_, Vec<String>> {
        // A panic while holding the lock leaves the log usable: it is only a list of strings.
        self.messages.lock().unwrap_or_else(|e| e.into_inner())
    }
}

unsafe extern "system" fn on_validation_message(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: `user` is the `ValidationLog` inside an `Arc` that outlives the messenger, and the
    // layer passes valid callback data for the duration of the call.
    unsafe {
        let log = &*(user as *const ValidationLog);
        let text = if data.is_null() || (*data).p_message.is_null() {
            "(no message)".to_string()
        } else {
            CStr::from_ptr((*data).p_message)
                .to_string_lossy()
                .into_owned()
        };
        let level = if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
            "error"
        } else {
            "warning"
        };
        log.lock().push(format!("[{level}] {text}"));
    }
    vk::FALSE
}

/// Device state shared by the context and every resource made from it; resources hold an `Arc`
/// so that the device outlives them whatever order things are dropped in.
pub(crate) struct DeviceShared {
    pub(crate) _entry: ash::Entry,
    pub(crate) instance: ash::Instance,
    debug_utils: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    pub(crate) physical: vk::PhysicalDevice,
    pub(crate) device: ash::Device,
    pub(crate) queue: Mutex<vk::Queue>,
    pub(crate) queue_family: u32,
    pub(crate) command_pool: Mutex<vk::CommandPool>,
    /// Submission objects kept between submissions (`submit_slot`).
    pub(crate) submit_slots: Mutex<Vec<super::submit_slot::SubmitSlot>>,
    /// Vulkan objects created for submissions since the device was opened.
    pub(crate) objects_created: std::sync::atomic::AtomicU64,
    /// Buffers and images given memory since the device was opened (`Context::allocations`).
    pub(crate) allocations: std::sync::atomic::AtomicU64,
    pub(crate) allocator: ManuallyDrop<Mutex<Allocator>>,
    pub(crate) properties: vk::PhysicalDeviceProperties,
    pub(crate) timestamp_valid_bits: u32,
    pub(crate) features: vk::PhysicalDeviceFeatures,
    pub(crate) validation_log: Arc<ValidationLog>,
    pub(crate) validating: bool,
    pub(crate) info: DeviceInfo,
}

impl DeviceShared {
    pub(crate) fn lock_slots(&self) -> MutexGuard<'_, Vec<super::submit_slot::SubmitSlot>> {
        self.submit_slots.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub(crate) fn lock_command_pool(&self) -> MutexGuard<'_, vk::CommandPool> {
        self.command_pool.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub(crate) fn count_created(&self, n: u64) {
        self.objects_created
            .fetch_add(n, std::sync::atomic::Ordering::Relaxed);
    }

    pub(crate) fn allocator(&self) -> MutexGuard<'_, Allocator> {
        self.allocator.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Turns messages logged since the last check into an error for the caller at hand.
    pub(crate) fn check_validation(&self) -> GpuResult<()> {
        if !self.validating {
            return Ok(());
        }
        let messages = self.validation_log.take();
        if messages.is_empty() {
            Ok(())
        } else {
            Err(GpuError::Validation(messages))
        }
    }
}

impl Drop for DeviceShared {
    fn drop(&mut self) {
        // SAFETY: every resource holds an Arc to this struct, so none is alive any more; the
        // device is idle after the wait, and objects are destroyed children first.
        unsafe {
            let _ = self.device.device_wait_idle();
            let slots = std::mem::take(
                self.submit_slots
                    .get_mut()
                    .unwrap_or_else(|e| e.into_inner()),
            );
            for mut slot in slots {
                slot.destroy(self);
            }
            ManuallyDrop::drop(&mut self.allocator);
            let pool = *self
                .command_pool
                .get_mut()
                .unwrap_or_else(|e| e.into_inner());
            self.device.destroy_command_pool(pool, None);
            self.device.destroy_device(None);
            if let Some((utils, messenger)) = self.debug_utils.take() {
                utils.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

/// The GPU: one device and one queue that can do compute and graphics. Cheap to clone.
#[derive(Clone)]
pub struct Context {
    pub(crate) shared: Arc<DeviceShared>,
}

fn load_entry() -> GpuResult<ash::Entry> {
    // SAFETY: loading the system Vulkan loader runs its initialisers; nothing else is touched.
    unsafe { ash::Entry::load() }.map_err(|e| GpuError::NoLoader(e.to_string()))
}

fn layer_installed(entry: &ash::Entry, name: &CStr) -> bool {
    // SAFETY: plain enumeration call on a loaded entry.
    let layers = unsafe { entry.enumerate_instance_layer_properties() }.unwrap_or_default();
    layers
        .iter()
        .any(|l| l.layer_name_as_c_str().map(|n| n == name).unwrap_or(false))
}

fn messenger_info<'a>(log: &Arc<ValidationLog>) -> vk::DebugUtilsMessengerCreateInfoEXT<'a> {
    vk::DebugUtilsMessengerCreateInfoEXT::default()
        .message_severity(
            vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
                | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
        )
        .message_type(vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION)
        .pfn_user_callback(Some(on_validation_message))
        .user_data(Arc::as_ptr(log) as *mut c_void)
}

fn create_instance(
    entry: &ash::Entry,
    validate: bool,
    log: &Arc<ValidationLog>,
) -> GpuResult<ash::Instance> {
    let app = vk::ApplicationInfo::default()
        .application_name(c"ocular")
        .application_version(vk::make_api_version(0, 0, 1, 0))
        .engine_name(c"ocular")
        .api_version(API_VERSION);
    let layers = if validate {
        vec![VALIDATION_LAYER.as_ptr()]
    } else {
        vec![]
    };
    let extensions = if validate {
        vec![ash::ext::debug_utils::NAME.as_ptr()]
    } else {
        vec![]
    };
    // Chained so that instance creation and destruction are validated too.
    let mut messenger = messenger_info(log);
    let mut info = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_layer_names(&layers)
        .enabled_extension_names(&extensions);
    // Synchronization validation checks the barriers the recorder derives from declared
    // access (src/gpu/access.rs): a missing dependency is a validation error in every test.
    let enables = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&enables);
    if validate {
        info = info.push_next(&mut messenger).push_next(&mut features);
    }
    // SAFETY: all pointers in `info` outlive the call.
    unsafe { entry.create_instance(&info, None) }.map_err(|result| match result {
        vk::Result::ERROR_INCOMPATIBLE_DRIVER => GpuError::NoDevice,
        result => GpuError::Vulkan {
            call: "vkCreateInstance",
            result,
        },
    })
}

fn version_string(v: u32) -> String {
    format!(
        "{}.{}.{}",
        vk::api_version_major(v),
        vk::api_version_minor(v),
        vk::api_version_patch(v)
    )
}

fn describe(instance: &ash::Instance, index: usize, physical: vk::PhysicalDevice) -> DeviceInfo {
    // SAFETY: `physical` comes from this instance's enumeration.
    let (props, driver, memory, families, max_allocation, subgroup) = unsafe {
        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        let mut maintenance3 = vk::PhysicalDeviceMaintenance3Properties::default();
        let mut subgroup = vk::PhysicalDeviceSubgroupProperties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default()
            .push_next(&mut driver)
            .push_next(&mut maintenance3)
            .push_next(&mut subgroup);
        instance.get_physical_device_properties2(physical, &mut props2);
        let props = props2.properties;
        let subgroup = (subgroup.supported_stages, subgroup.supported_operations);
        let max_allocation = maintenance3.max_memory_allocation_size;
        let driver_name = driver
            .driver_info_as_c_str()
            .ok()
            .map(|s| s.to_string_lossy().into_owned())
            .filter(|s| !s.is_empty())
            .or_else(|| {
                driver
                    .driver_name_as_c_str()
                    .ok()
                    .map(|s| s.to_string_lossy().into_owned())
            })
            .unwrap_or_default();
        let memory = instance.get_physical_device_memory_properties(physical);
        let families = instance.get_physical_device_queue_family_properties(physical);
        (
            props,
            driver_name,
            memory,
            families,
            max_allocation,
            subgroup,
        )
    };
    let name = props
        .device_name_as_c_str()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|_| "(unnamed)".into());
    let device_local: u64 = memory.memory_heaps[..memory.memory_heap_count as usize]
        .iter()
        .filter(|h| h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL))
        .map(|h| h.size)
        .sum();
    let unsuitable = if props.api_version < API_VERSION {
        Some(format!(
            "Vulkan {} is too old (ocular needs 1.2)",
            version_string(props.api_version)
        ))
    } else if pick_queue_family(&families).is_none() {
        Some("no queue family supports graphics and compute".into())
    } else if !subgroup.0.contains(vk::ShaderStageFlags::COMPUTE)
        || !subgroup.1.contains(vk::SubgroupFeatureFlags::ARITHMETIC)
    {
        // The convolution ORs its rows' fragment masks across the subgroup.
        Some("no subgroup arithmetic in compute shaders".into())
    } else {
        None
    };
    DeviceInfo {
        index,
        name,
        kind: DeviceKind::from_vk(props.device_type),
        vulkan_version: version_string(props.api_version),
        driver,
        device_local_mib: device_local / (1024 * 1024),
        max_allocation_mib: max_allocation / (1024 * 1024),
        unsuitable,
    }
}

fn pick_queue_family(families: &[vk::QueueFamilyProperties]) -> Option<u32> {
    let want = vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE;
    families
        .iter()
        .position(|f| f.queue_flags.contains(want) && f.queue_count > 0)
        .map(|i| i as u32)
}

fn enumerate(instance: &ash::Instance) -> GpuResult<Vec<(vk::PhysicalDevice, DeviceInfo)>> {
    // SAFETY: plain enumeration on a live instance.
    let physicals =
        unsafe { instance.enumerate_physical_devices() }.vk("vkEnumeratePhysicalDevices")?;
    Ok(physicals
        .into_iter()
        .enumerate()
        .map(|(i, p)| (p, describe(instance, i, p)))
        .collect())
}

/// Picks the device the user asked for (index or name substring), else the most capable
/// usable one; returns its position in `devices`.
fn select(devices: &[DeviceInfo], query: Option<&str>) -> GpuResult<usize> {
    if devices.is_empty() {
        return Err(GpuError::NoDevice);
    }
    let chosen = match query {
        Some(q) => {
            let q_lower = q.trim().to_lowercase();
            // A number is an index and nothing else: "5" must not fall back to a name that
            // happens to contain the digit (such as "LLVM 15.0.6").
            match q.trim().parse::<usize>() {
                Ok(i) => Some(i).filter(|&i| i < devices.len()),
                Err(_) => devices
                    .iter()
                    .position(|d| d.name.to_lowercase().contains(&q_lower)),
            }
            .ok_or_else(|| GpuError::DeviceNotFound {
                query: q.to_string(),
                available: devices
                    .iter()
                    .map(|d| format!("{}: {}", d.index, d.name))
                    .collect::<Vec<_>>()
                    .join(", "),
            })?
        }
        None => devices
            .iter()
            .filter(|d| d.unsuitable.is_none())
            .min_by_key(|d| (d.kind.preference(), d.index))
            .map(|d| d.index)
            .unwrap_or(0),
    };
    if let Some(reason) = &devices[chosen].unsuitable {
        return Err(GpuError::DeviceUnsuitable {
            device: devices[chosen].name.clone(),
            reason: reason.clone(),
        });
    }
    Ok(chosen)
}

/// The devices the loader sees (in `--device <index>` order) and the index of the one a
/// context created with `query` would use.
pub fn resolve_device(query: Option<&str>) -> GpuResult<(Vec<DeviceInfo>, usize)> {
    let devices = list_devices()?;
    let chosen = select(&devices, query)?;
    Ok((devices, chosen))
}

/// Lists the physical devices the loader sees, in the order `--device <index>` uses.
pub fn list_devices() -> GpuResult<Vec<DeviceInfo>> {
    let entry = load_entry()?;
    let log = Arc::new(ValidationLog::default());
    let instance = create_instance(&entry, false, &log)?;
    let result = enumerate(&instance).map(|v| v.into_iter().map(|(_, d)| d).collect());
    // SAFETY: no child objects were created.
    unsafe { instance.destroy_instance(None) };
    result
}

impl Context {
    pub fn new(options: &ContextOptions) -> GpuResult<Context> {
        let entry = load_entry()?;
        let validate = match options.validation {
            Validation::Off => false,
            Validation::IfInstalled => layer_installed(&entry, VALIDATION_LAYER),
            Validation::Required => {
                if !layer_installed(&entry, VALIDATION_LAYER) {
                    return Err(GpuError::Unsupported(
                        "validation was required but VK_LAYER_KHRONOS_validation is not \
                         installed (Debian/Ubuntu: apt-get install vulkan-validationlayers)"
                            .into(),
                    ));
                }
                true
            }
        };
        let log = Arc::new(ValidationLog::default());
        let instance = create_instance(&entry, validate, &log)?;
        // From here on, failures must destroy the instance: build the rest in a helper.
        match Self::with_instance(entry.clone(), instance.clone(), validate, log, options) {
            Ok(ctx) => Ok(ctx),
            Err(e) => {
                // SAFETY: with_instance destroyed whatever it created before failing.
                unsafe { instance.destroy_instance(None) };
                Err(e)
            }
        }
    }

    fn with_instance(
        entry: ash::Entry,
        instance: ash::Instance,
        validate: bool,
        log: Arc<ValidationLog>,
        options: &ContextOptions,
    ) -> GpuResult<Context> {
        let devices = enumerate(&instance)?;
        let infos: Vec<DeviceInfo> = devices.iter().map(|(_, d)| d.clone()).collect();
        let (physical, info) = devices[select(&infos, options.device.as_deref())?].clone();
        // SAFETY: `physical` belongs to `instance`.
        let (properties, families) = unsafe {
            (
                instance.get_physical_device_properties(physical),
                instance.get_physical_device_queue_family_properties(physical),
            )
        };
        let queue_family = pick_queue_family(&families).expect("checked by describe()");
        let priorities = [1.0f32];
        let queue_info = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        // Passes write 3D images whose format is chosen at run time (RGBA16F or RGBA32F), so
        // storage images without a format qualifier are needed where the device has them.
        // SAFETY: `physical` belongs to `instance`.
        let available = unsafe { instance.get_physical_device_features(physical) };
        let features = vk::PhysicalDeviceFeatures::default()
            .shader_storage_image_write_without_format(
                available.shader_storage_image_write_without_format == vk::TRUE,
            )
            .shader_storage_image_read_without_format(
                available.shader_storage_image_read_without_format == vk::TRUE,
            );
        let info_create = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_info)
            .enabled_features(&features);
        // SAFETY: pointers in the create info outlive the call.
        let device =
            unsafe { instance.create_device(physical, &info_create, None) }.vk("vkCreateDevice")?;
        // SAFETY: the queue was requested above; the pool is for that family.
        let (queue, pool) = unsafe {
            let queue = device.get_device_queue(queue_family, 0);
            let pool_info = vk::CommandPoolCreateInfo::default()
                .queue_family_index(queue_family)
                .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
            match device.create_command_pool(&pool_info, None) {
                Ok(pool) => (queue, pool),
                Err(e) => {
                    device.destroy_device(None);
                    return Err(e).vk("vkCreateCommandPool");
                }
            }
        };
        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        });
        let allocator = match allocator {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: nothing else was created from the device.
                unsafe {
                    device.destroy_command_pool(pool, None);
                    device.destroy_device(None);
                }
                return Err(GpuError::Unsupported(format!("memory allocation ({e})")));
            }
        };
        let debug_utils = if validate {
            let utils = ash::ext::debug_utils::Instance::new(&entry, &instance);
            // SAFETY: the log outlives the messenger (both live in DeviceShared, and the
            // messenger is destroyed first).
            let messenger =
                unsafe { utils.create_debug_utils_messenger(&messenger_info(&log), None) }
                    .vk("vkCreateDebugUtilsMessengerEXT")?;
            Some((utils, messenger))
        } else {
            None
        };
        Ok(Context {
            shared: Arc::new(DeviceShared {
                _entry: entry,
                instance,
                debug_utils,
                physical,
                device,
                queue: Mutex::new(queue),
                queue_family,
                command_pool: Mutex::new(pool),
                submit_slots: Mutex::new(Vec::new()),
                objects_created: std::sync::atomic::AtomicU64::new(0),
                allocations: std::sync::atomic::AtomicU64::new(0),
                allocator: ManuallyDrop::new(Mutex::new(allocator)),
                properties,
                timestamp_valid_bits: families[queue_family as usize].timestamp_valid_bits,
                features,
                validation_log: log,
                validating: validate,
                info,
            }),
        })
    }

    pub fn device_info(&self) -> &DeviceInfo {
        &self.shared.info
    }

    pub fn limits(&self) -> &vk::PhysicalDeviceLimits {
        &self.shared.properties.limits
    }

    /// Vulkan objects (command buffers, fences, query and descriptor pools) created for
    /// submissions so far: constant across steady-state frames, which reuse them.
    pub fn submission_objects_created(&self) -> u64 {
        self.shared
            .objects_created
            .load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Whether the validation layer is active on this context.
    pub fn is_validating(&self) -> bool {
        self.shared.validating
    }

    /// The validation log; it stays readable after the context is gone, so tests can check
    /// for messages produced during destruction too.
    pub fn validation_log(&self) -> Arc<ValidationLog> {
        self.shared.validation_log.clone()
    }

    /// Fails with the messages the validation layer produced since the last check.
    pub fn check_validation(&self) -> GpuResult<()> {
        self.shared.check_validation()
    }

    /// Whether shaders may write storage images declared without a format qualifier.
    pub fn can_write_images_without_format(&self) -> bool {
        self.shared
            .features
            .shader_storage_image_write_without_format
            == vk::TRUE
    }

    /// The queue family all work is submitted to (graphics and compute).
    pub fn queue_family_index(&self) -> u32 {
        self.shared.queue_family
    }

    pub fn raw_device(&self) -> &ash::Device {
        &self.shared.device
    }

    /// Whether the device supports `usage` features for `format` with optimal tiling.
    pub fn format_supports(&self, format: vk::Format, features: vk::FormatFeatureFlags) -> bool {
        // SAFETY: query on a live physical device.
        let props = unsafe {
            self.shared
                .instance
                .get_physical_device_format_properties(self.shared.physical, format)
        };
        props.optimal_tiling_features.contains(features)
    }

    pub(crate) fn image_format_properties(
        &self,
        format: vk::Format,
        image_type: vk::ImageType,
        usage: vk::ImageUsageFlags,
    ) -> Option<vk::ImageFormatProperties> {
        // SAFETY: query on a live physical device.
        unsafe {
            self.shared
                .instance
                .get_physical_device_image_format_properties(
                    self.shared.physical,
                    format,
                    image_type,
                    vk::ImageTiling::OPTIMAL,
                    usage,
                    vk::ImageCreateFlags::empty(),
                )
                .ok()
        }
    }
}
