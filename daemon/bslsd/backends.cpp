#include "backends.h"

#include <mutex>

#include "bsls/framestore/dev_port_io.h"
#include "bsls/framestore/ioperm_port_io.h"
#include "bsls/framestore/isa_card_emulator.h"
#include "bsls/framestore/isa_framestore.h"
#include "bsls/framestore/simulated_framestore.h"
#include "bsls/framestore/usb_device_model.h"
#include "bsls/framestore/usb_framestore.h"
#include "bsls/slides/emulated_slide_changer.h"

namespace bsls::bslsd {

namespace {

framestore::PortRange IsaPorts(std::uint16_t base) { return {base, 4}; }

// The slide the projector shows now, for the simulated pictures: 0 while a
// change is under way or nothing is confirmed in place.
framestore::SlideSource SlideSourceOf(slides::SlideController* slides) {
  if (slides == nullptr) return {};
  return [slides] {
    const slides::SlideState state = slides->State();
    return state.in_place && !state.moving ? state.slide : 0;
  };
}

framestore::SimulatedFramestoreParams SimulatedParams(const Config& config,
                                                      slides::SlideController* slides) {
  framestore::SimulatedFramestoreParams params;
  params.noise_sigma = config.framestore.simulated_noise_sigma;
  params.frame_rate_hz = config.framestore.simulated_frame_rate_hz;
  params.breathing_amplitude_mm = config.framestore.simulated_breathing_mm;
  params.slide = SlideSourceOf(slides);
  return params;
}

// The ISA card emulator's cameras: the simulated head, one picture per video
// frame and input (the emulator asks for each field; the last is kept).
class SimulatedVideo {
 public:
  explicit SimulatedVideo(std::unique_ptr<framestore::SimulatedFramestore> source)
      : source_(std::move(source)) {}

  std::shared_ptr<const framestore::VideoFrame> Picture(int input, std::int64_t frame) {
    std::lock_guard lock(mutex_);
    if (last_ && input == last_input_ && frame == last_frame_) return last_;
    const auto camera = static_cast<framestore::Camera>(input);
    if (!source_->capabilities().HasCamera(camera) || !source_->SelectCamera(camera).ok())
      return nullptr;  // no camera on this input: no sync
    Result<framestore::GreyFrame> grabbed = source_->Grab();
    if (!grabbed.ok()) return nullptr;
    auto picture = std::make_shared<framestore::VideoFrame>();
    picture->width = grabbed->width;
    picture->height = grabbed->height;
    picture->pixels.resize(static_cast<std::size_t>(grabbed->width) * grabbed->height);
    for (int y = 0; y < grabbed->height; ++y)
      std::copy_n(grabbed->pixels.begin() + static_cast<std::ptrdiff_t>(y) * grabbed->stride,
                  grabbed->width,
                  picture->pixels.begin() + static_cast<std::ptrdiff_t>(y) * grabbed->width);
    last_ = picture;
    last_input_ = input;
    last_frame_ = frame;
    return picture;
  }

 private:
  std::mutex mutex_;
  std::unique_ptr<framestore::SimulatedFramestore> source_;
  std::shared_ptr<const framestore::VideoFrame> last_;
  int last_input_ = -1;
  std::int64_t last_frame_ = -1;
};

// The video inputs of an emulated device (ISA card or USB firmware model): a
// still simulated head per camera, rendered up front (a view renders in tens
// of milliseconds, longer than the card's digitise timeout); the emulated
// device keeps its own video timing.
Result<framestore::VideoSource> EmulatedVideo(const Config& config,
                                              slides::SlideController* slides) {
  framestore::SimulatedFramestoreParams params = SimulatedParams(config, slides);
  params.paced = false;
  params.breathing_amplitude_mm = 0.0;
  params.breathing_phases = 1;
  Result<std::unique_ptr<framestore::SimulatedFramestore>> source =
      framestore::SimulatedFramestore::Open(params);
  if (!source.ok()) return source.status();
  auto video = std::make_shared<SimulatedVideo>(std::move(source).value());
  for (int input = 0; input < 2; ++input) video->Picture(input, -2);
  return framestore::VideoSource(
      [video](int input, std::int64_t frame) { return video->Picture(input, frame); });
}

}  // namespace

Result<PrivilegedDevices> OpenPrivileged(const Config& config) {
  PrivilegedDevices devices;
  if (config.framestore.backend != Backend::kIsa) return devices;
  const framestore::PortRange ports = IsaPorts(config.framestore.isa_base);
  if (config.framestore.isa_port_access == "ioperm") {
    Result<std::unique_ptr<framestore::IopermPortIo>> io = framestore::IopermPortIo::Open(ports);
    if (!io.ok()) return io.status();
    devices.port_io = std::move(io).value();
  } else {
    Result<std::unique_ptr<framestore::DevPortIo>> io = framestore::DevPortIo::Open(ports);
    if (!io.ok()) return io.status();
    devices.port_io = std::move(io).value();
  }
  return devices;
}

Result<std::unique_ptr<slides::SlideController>> OpenSlides(const Config& config,
                                                            service::EventHub* events) {
  std::unique_ptr<slides::GpioLines> lines;
  switch (config.slides.backend) {
    case SlideBackend::kNone:
      return std::unique_ptr<slides::SlideController>();
    case SlideBackend::kSimulated:
      lines = std::make_unique<slides::EmulatedSlideChanger>(config.slides.controller);
      break;
    case SlideBackend::kGpio: {
      Result<std::unique_ptr<slides::GpioLines>> opened =
          slides::OpenLibgpiodChip(config.slides.controller.chip);
      if (!opened.ok()) return opened.status();
      lines = std::move(opened).value();
      break;
    }
  }
  Result<std::unique_ptr<slides::SlideController>> controller =
      slides::SlideController::Open(std::move(lines), config.slides.controller);
  if (!controller.ok()) return controller.status();
  if (events) {
    (*controller)->SetListener([events](const slides::SlideState& state) {
      v1::Event event;
      v1::SlideState* out = event.mutable_slide_changed();
      out->set_slide(state.slide);
      out->set_in_place(state.in_place);
      out->set_moving(state.moving);
      out->set_lamp_on(state.lamp_on);
      out->set_focus_position(state.focus_position);
      out->set_last_error(state.last_error);
      events->Publish(std::move(event));
    });
  }
  return controller;
}

Result<std::unique_ptr<framestore::Framestore>> OpenFramestore(const Config& config,
                                                               PrivilegedDevices privileged,
                                                               slides::SlideController* slides) {
  switch (config.framestore.backend) {
    case Backend::kSimulated: {
      Result<std::unique_ptr<framestore::SimulatedFramestore>> store =
          framestore::SimulatedFramestore::Open(SimulatedParams(config, slides));
      if (!store.ok()) return store.status();
      return std::unique_ptr<framestore::Framestore>(std::move(store).value());
    }
    case Backend::kIsa:
    case Backend::kEmulatedIsa: {
      std::unique_ptr<framestore::PortIo> io = std::move(privileged.port_io);
      if (config.framestore.backend == Backend::kEmulatedIsa) {
        Result<framestore::VideoSource> video = EmulatedVideo(config, slides);
        if (!video.ok()) return video.status();
        framestore::IsaCardEmulatorParams card;
        card.base = config.framestore.isa_base;
        io = std::make_unique<framestore::IsaCardEmulator>(card, std::move(video).value());
      }
      if (!io) return Status(ErrorCode::kInternal, "the ISA backend's ports were not opened");
      framestore::IsaFramestoreParams params;
      params.base = config.framestore.isa_base;
      Result<std::unique_ptr<framestore::IsaFramestore>> store =
          framestore::IsaFramestore::Open(std::move(io), params);
      if (!store.ok()) return store.status();
      return std::unique_ptr<framestore::Framestore>(std::move(store).value());
    }
    case Backend::kUsb:
    case Backend::kEmulatedUsb: {
      std::unique_ptr<framestore::UsbTransport> transport;
      if (config.framestore.backend == Backend::kEmulatedUsb) {
        Result<framestore::VideoSource> video = EmulatedVideo(config, slides);
        if (!video.ok()) return video.status();
        transport = std::make_unique<framestore::UsbDeviceModel>(std::move(video).value());
      } else {
        Result<std::unique_ptr<framestore::UsbTransport>> opened =
            framestore::OpenLibusbTransport();
        if (!opened.ok()) return opened.status();
        transport = std::move(opened).value();
      }
      Result<std::unique_ptr<framestore::UsbFramestore>> store =
          framestore::UsbFramestore::Open(std::move(transport));
      if (!store.ok()) return store.status();
      return std::unique_ptr<framestore::Framestore>(std::move(store).value());
    }
  }
  return Status(ErrorCode::kInvalidArgument, "framestore.backend is not known");
}

}  // namespace bsls::bslsd
