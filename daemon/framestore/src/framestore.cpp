#include "bsls/framestore/framestore.h"

#include <algorithm>

namespace bsls::framestore {

std::string ToString(Camera camera) {
  switch (camera) {
    case Camera::kLeft:
      return "left";
    case Camera::kRight:
      return "right";
    case Camera::kThird:
      return "third";
  }
  return "camera " + std::to_string(static_cast<int>(camera));
}

std::optional<Camera> ParseCamera(std::string_view text) {
  for (Camera camera : {Camera::kLeft, Camera::kRight, Camera::kThird}) {
    if (text == ToString(camera)) return camera;
  }
  return std::nullopt;
}

bool Capabilities::HasCamera(Camera camera) const {
  return std::find(cameras.begin(), cameras.end(), camera) != cameras.end();
}

}  // namespace bsls::framestore
