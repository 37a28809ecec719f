// The simulated framestore: live frames of a simulated head in the thesis rig
// (simulator/), so bslsd runs on any machine without hardware. It is the
// daemon's default backend. Frames follow the selected camera and the slide
// in place (slide 1 reference cross, 2 left brick, 3 right brick, 0 none: the
// projector shows nothing), the head breathes (a slow sinusoidal shift along
// the viewing axis) and every frame has fresh sensor noise. Grabs are paced
// like a camera's: one frame per 1 / frame_rate_hz, the next frame time after
// the request.
//
// Rendering a view costs tens of milliseconds, so the noiseless image of
// every (camera, slide, breathing phase) is rendered once, on first use, and
// kept; a grab adds gain and noise (about a millisecond at 512 x 512).
//
// Thread-safety: as the Framestore interface (one capture thread); the
// slide source is called from that thread.
#ifndef BSLS_FRAMESTORE_SIMULATED_FRAMESTORE_H_
#define BSLS_FRAMESTORE_SIMULATED_FRAMESTORE_H_

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <tuple>

#include "bsls/framestore/framestore.h"

namespace bsls::framestore {

// The slide in place now: 1, 2 or 3, or 0 when none is (moving, lamp off).
using SlideSource = std::function<int()>;

struct SimulatedFramestoreParams {
  double frame_rate_hz = 25.0;          // PAL, thesis Appendix C
  double breathing_amplitude_mm = 0.5;  // peak shift of the head along z
  double breathing_period_s = 4.0;
  int breathing_phases = 4;  // rendered phases per period, >= 1
  double noise_sigma = 3.0;  // grey levels at nominal gain
  std::uint32_t seed = 1;    // seeds the per-frame noise
  bool paced = true;         // wait for the next frame time (false: as fast as rendered)
  SlideSource slide;         // empty: slide 2 for the left camera, 3 for the right

  // True when usable; otherwise `error` names the field and the reason.
  bool IsValid(std::string* error) const;
};

// Gain steps of the simulated camera: code / 128 times the rendered grey level.
inline constexpr int kSimulatedGainMin = 32;
inline constexpr int kSimulatedGainMax = 255;
inline constexpr int kSimulatedGainNominal = 128;

class SimulatedFramestore final : public Framestore {
 public:
  // Loads the face model (simulator data); kUnavailable naming the file when
  // it cannot, kInvalidArgument for bad params.
  static Result<std::unique_ptr<SimulatedFramestore>> Open(const SimulatedFramestoreParams& params);
  ~SimulatedFramestore() override;

  const Capabilities& capabilities() const override { return capabilities_; }
  Status SelectCamera(Camera camera) override;
  Status SetGain(int gain) override;
  Camera camera() const override { return camera_; }
  int gain() const override { return gain_; }
  Result<GreyFrame> Grab(const GrabOptions& options = {}) override;

 private:
  struct View;
  explicit SimulatedFramestore(const SimulatedFramestoreParams& params);
  // The noiseless image of `camera` under `slide` at breathing `phase`.
  const View& ViewFor(Camera camera, int slide, int phase);

  SimulatedFramestoreParams params_;
  Capabilities capabilities_;
  Camera camera_ = Camera::kLeft;
  int gain_ = kSimulatedGainNominal;
  std::uint64_t sequence_ = 0;
  std::chrono::steady_clock::time_point epoch_;
  std::map<std::tuple<int, int, int>, std::unique_ptr<View>> views_;
};

}  // namespace bsls::framestore

#endif  // BSLS_FRAMESTORE_SIMULATED_FRAMESTORE_H_
