// An ability of a solver beside the facets of solver.h: the run loop's checks recorded into the
// advance before them (the GPU solver; RunLoop finds it by dynamic_cast).
#pragma once

namespace phyxel {

class CheckPrefetch {
 public:
  virtual ~CheckPrefetch() = default;
  // A hint before an advance: the run loop's checks (first_non_finite, max_norms) of its end
  // state follow it. The GPU solver records them into the advance's last submission; they
  // return those results until a call that may change the state.
  virtual void prefetch_checks() = 0;
};

}  // namespace phyxel
