use ash::vk;

/// Everything that can go wrong on the GPU side, phrased so that a person can act on it.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error(
        "no Vulkan loader found ({0}); install it (Debian/Ubuntu: apt-get install libvulkan1 \
         mesa-vulkan-drivers) or run ci/setup.sh"
    )]
    NoLoader(String),
    #[error(
        "no Vulkan device found; install a GPU driver, or Mesa's CPU driver for software \
         rendering (Debian/Ubuntu: apt-get install mesa-vulkan-drivers)"
    )]
    NoDevice,
    #[error("--device / OCULAR_DEVICE: no device matches \"{query}\"; available: {available}")]
    DeviceNotFound { query: String, available: String },
    #[error("device \"{device}\" cannot run ocular: {reason}")]
    DeviceUnsuitable { device: String, reason: String },
    #[error(
        "out of device memory allocating {what}; use a smaller frame or settings, or another \
         device (--device)"
    )]
    OutOfDeviceMemory { what: String },
    #[error("the device does not support {0}")]
    Unsupported(String),
    #[error("Vulkan validation reported {} message(s); first: {}", .0.len(), .0.first().map(String::as_str).unwrap_or(""))]
    Validation(Vec<String>),
    #[error("the GPU device was lost (driver crash or reset) during {0}")]
    DeviceLost(String),
    #[error("Vulkan call {call} failed: {result}")]
    Vulkan {
        call: &'static str,
        result: vk::Result,
    },
    #[error("GPU pass \"{pass}\": {message}")]
    Usage { pass: String, message: String },
    #[error(
        "the \"{pass}\" pass left {unwritten} of {total} pixels unwritten (the first at x {x}, \
         y {y}): the device dropped part of the work, so no image is returned"
    )]
    DroppedWork {
        pass: String,
        unwritten: usize,
        total: usize,
        x: usize,
        y: usize,
    },
}

pub type GpuResult<T> = Result<T, GpuError>;

/// Attaches the failing call's name to a raw `vk::Result`, turning the ones a person can act
/// on into the matching variant.
pub(crate) trait VkContext<T> {
    fn vk(self, call: &'static str) -> GpuResult<T>;
}

impl<T> VkContext<T> for Result<T, vk::Result> {
    fn vk(self, call: &'static str) -> GpuResult<T> {
        self.map_err(|result| match result {
            vk::Result::ERROR_OUT_OF_DEVICE_MEMORY | vk::Result::ERROR_OUT_OF_HOST_MEMORY => {
                GpuError::OutOfDeviceMemory {
                    what: format!("memory for {call}"),
                }
            }
            vk::Result::ERROR_DEVICE_LOST => GpuError::DeviceLost(call.to_string()),
            result => GpuError::Vulkan { call, result },
        })
    }
}
