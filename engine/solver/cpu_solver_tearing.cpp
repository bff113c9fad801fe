// CpuSolver: tearing (engine/solver/tearing.h; the GPU twin is
// compute/shaders/solver_force_tear.comp).
// At the end of a step, after the stress pass of its positions, every phyxel of the stress pass
// tests its live pairs to higher indices: a pair whose mean normal stress reaches the mean of
// the two strengths is severed as a cut severs one (logged with t = 0.5 and `torn`), and the
// precompute reruns for the phyxels whose rows changed. The step's forces stay those of the
// intact pairs; the next stress pass sees the tear.
#include <omp.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "engine/solver/cpu_solver.h"
#include "engine/solver/tearing.h"

namespace phyxel {

template <class Real>
void CpuSolver<Real>::apply_tears() {
  const long ns = static_cast<long>(stress_list_.size());
  const int threads = threads_for(ns);
  // (row, slot) of each pair that tears, per thread; a static schedule hands the threads
  // consecutive blocks in order, so joining them keeps the ascending (i, j) order.
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> found(size_t(std::max(threads, 1)));
#pragma omp parallel num_threads(threads)
  {
    std::vector<std::pair<uint32_t, uint32_t>>& mine = found[size_t(omp_get_thread_num())];
#pragma omp for schedule(static)
    for (long s = 0; s < ns; ++s) {
      const uint32_t i = stress_list_[s];
      if (!(tear_[i] > Real(0))) continue;
      const V3 xi = rest_[i] + u_[i];
      for (uint32_t k = nbr_.offset[i]; k < nbr_.offset[i + 1]; ++k) {
        const uint32_t j = nbr_.index[k];
        if (j <= i || w_[k] == Real(0)) continue;
        const Real threshold = pair_tear_threshold(tear_[i], tear_[j]);
        if (!(threshold > Real(0))) continue;
        if (no_fit_[i] || no_fit_[j]) {  // a phyxel left without a fit keeps no pair
          mine.emplace_back(i, k);
          continue;
        }
        // The normal stress is at most the mean of the largest principal values: most pairs
        // stop here (the slack keeps rounding from deciding).
        if (Real(0.5) * (max_principal_[i] + max_principal_[j]) < Real(0.9999) * threshold)
          continue;
        const Real s_ij = pair_normal_stress<Real>(cauchy_[i], cauchy_[j], xi, rest_[j] + u_[j]);
        if (pair_tears(s_ij, threshold)) mine.emplace_back(i, k);
      }
    }
  }
  std::vector<uint32_t> touched;
  for (const auto& list : found) {
    for (const auto& [i, k] : list) {
      if (!sever(i, k, 0.5f)) continue;
      severed_.back().torn = true;
      touched.push_back(i);
      touched.push_back(nbr_.index[k]);
    }
  }
  if (!touched.empty()) precompute_touched(touched);
}

template void CpuSolver<double>::apply_tears();
template void CpuSolver<float>::apply_tears();

}  // namespace phyxel
