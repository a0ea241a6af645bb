#include "motion_end.hpp"

namespace dh3::ctl {

bool MotionEnd::ends_motion(const HandEvent& event) const {
  switch (event.kind) {
    case EventKind::offline:
      return true;
    case EventKind::arrived:
    case EventKind::grasped:
    case EventKind::missed:
      return !rotation_ && event.target == target_;
    case EventKind::rotation_arrived:
    case EventKind::rotation_blocked:
      return rotation_ && event.target == target_;
    default:
      return false;
  }
}

void MotionEnd::offer(const HandEvent& event) {
  if (!ends_motion(event)) return;
  std::lock_guard lock(mutex_);
  if (!end_) end_ = event;
  changed_.notify_all();
}

}  // namespace dh3::ctl
