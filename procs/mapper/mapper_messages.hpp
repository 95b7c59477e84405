// LCM <-> mapper core conversion, in one place.
#pragma once

#include "dlslot/map_state_t.hpp"
#include "dlslot/slot_state_t.hpp"
#include "mapper/mapper.hpp"

namespace dlslot::mapper {

// The pose and the tracks of a SLOT_STATE (scan left empty).
MapperInput inputFromMsg(const slot_state_t& m);
loop_event_t toMsg(const LoopEvent& e);
map_state_t mapStateMsg(const Mapper& mapper, int frame, int64_t utime, const Pose& slot_pose,
                        const std::vector<LoopEvent>& new_events);

}  // namespace dlslot::mapper
