// bslsd's backend factory: the one place that turns the configuration into a
// Framestore and a SlideController. Split in two for least privilege:
// OpenPrivileged runs while the daemon still holds CAP_SYS_RAWIO and has a
// single thread (port I/O for the ISA card); the rest runs after the drop.
#ifndef BSLS_BSLSD_BACKENDS_H_
#define BSLS_BSLSD_BACKENDS_H_

#include <memory>

#include "bsls/framestore/framestore.h"
#include "bsls/framestore/port_io.h"
#include "bsls/service/event_hub.h"
#include "bsls/slides/slide_controller.h"
#include "config.h"

namespace bsls::bslsd {

// What only a privileged process can open.
struct PrivilegedDevices {
  std::unique_ptr<framestore::PortIo> port_io;  // the ISA card's ports (backend isa)
};

// Opens the port I/O of the ISA backend (nothing for the others). A kernel
// lockdown or a missing CAP_SYS_RAWIO is kPermissionDenied with the cause.
Result<PrivilegedDevices> OpenPrivileged(const Config& config);

// The configured slide controller (nullptr for slides.backend none); its
// state changes are published on `events`.
Result<std::unique_ptr<slides::SlideController>> OpenSlides(const Config& config,
                                                            service::EventHub* events);

// The configured framestore. The simulated backends show the slide that
// `slides` has in place (when given).
Result<std::unique_ptr<framestore::Framestore>> OpenFramestore(const Config& config,
                                                               PrivilegedDevices privileged,
                                                               slides::SlideController* slides);

}  // namespace bsls::bslsd

#endif  // BSLS_BSLSD_BACKENDS_H_
