// The per-pair buffers (the CSR neighbour index and the pair weights), each held in two
// buffers: lo holds pairs [0, n) and hi pairs [n, pairs), n a specialization constant.
// One storage-buffer binding reaches at most maxStorageBufferRange bytes (4 GiB on NVIDIA, at
// about 41M phyxels of a lattice), so a larger scene binds the rest as hi; a smaller one binds
// the whole buffer as lo (and again as hi, never read). See compute/pair_buffer.h. Unless the
// pipeline's specialization constant 0 (kPairsSplit, below) is set, only lo is read.
//
// Define before including:
//   PHYXEL_PAIR_INDEX_BINDING, PHYXEL_PAIR_INDEX_HI_BINDING,
//   PHYXEL_PAIR_WEIGHT_BINDING, PHYXEL_PAIR_WEIGHT_HI_BINDING   the four binding numbers
//   PHYXEL_PAIR_ACCESS   0: read both (float weights; the step passes)
//                        1: write the index, write float weights (nbr_pairs)
//                        2: read the index, read and write the weights as uint bits (the
//                           passes that sever pairs: tool_sever, solver_force_tear)
//   PHYXEL_PAIR_WEIGHT_COHERENT   (optional, access 2) the weights coherent: a workgroup that
//                           reads what others severed in the same dispatch (tool_sever's last)
#ifndef PHYXEL_PAIR_BUFFERS_GLSL
#define PHYXEL_PAIR_BUFFERS_GLSL

#if PHYXEL_PAIR_ACCESS == 1
#define PHYXEL_PAIR_INDEX_QUALIFIER
#define PHYXEL_PAIR_WEIGHT_QUALIFIER writeonly
#else
#define PHYXEL_PAIR_INDEX_QUALIFIER readonly
#if PHYXEL_PAIR_ACCESS == 2 && defined(PHYXEL_PAIR_WEIGHT_COHERENT)
#define PHYXEL_PAIR_WEIGHT_QUALIFIER coherent
#elif PHYXEL_PAIR_ACCESS == 2
#define PHYXEL_PAIR_WEIGHT_QUALIFIER
#else
#define PHYXEL_PAIR_WEIGHT_QUALIFIER readonly
#endif
#endif

#if PHYXEL_PAIR_ACCESS == 2
#define PHYXEL_PAIR_WEIGHT_TYPE uint
#else
#define PHYXEL_PAIR_WEIGHT_TYPE float
#endif

layout(std430, binding = PHYXEL_PAIR_INDEX_BINDING) PHYXEL_PAIR_INDEX_QUALIFIER buffer IndexLo {
  uint index_lo[];
};
layout(std430, binding = PHYXEL_PAIR_INDEX_HI_BINDING) PHYXEL_PAIR_INDEX_QUALIFIER buffer IndexHi {
  uint index_hi[];
};
layout(std430, binding = PHYXEL_PAIR_WEIGHT_BINDING) PHYXEL_PAIR_WEIGHT_QUALIFIER buffer WeightLo {
  PHYXEL_PAIR_WEIGHT_TYPE weight_lo[];
};
layout(std430, binding = PHYXEL_PAIR_WEIGHT_HI_BINDING) PHYXEL_PAIR_WEIGHT_QUALIFIER
    buffer WeightHi {
  PHYXEL_PAIR_WEIGHT_TYPE weight_hi[];
};

// Specialization constant 0: whether the pipeline may see a second part (SolverKernels sets it
// where the scene's pairs exceed one part). Where it is false every access is lo's and the
// driver's compiler drops the test: the code of one binding. (Tested per pair, the split cost
// the stress pass 40 % at 1M phyxels on an H200.)
layout(constant_id = 0) const bool kPairsSplit = false;
// Specialization constant 1: the pairs in lo where there is a second part (the same for the
// index and the weights: both are 4 bytes a pair). A constant, not the lo binding's length():
// NVIDIA's driver (580.159.04) gave wrong results for every pair in a lo binding of 3 GB and
// more when the shader took its length(), while the same binding read without length() was
// right (docs/performance-log.md, "Past one binding").
layout(constant_id = 1) const uint kPairsLo = 0xffffffffu;

uint pairs_lo() { return kPairsLo; }

// Neighbour j of pair slot k.
uint nbr_index(uint k) {
  const uint n = pairs_lo();
  if (!kPairsSplit || k < n) return index_lo[k];
  return index_hi[k - n];
}

#if PHYXEL_PAIR_ACCESS == 0
// w_ij of pair slot k as stored (0: a severed or removed pair).
float pair_weight(uint k) {
  const uint n = pairs_lo();
  if (!kPairsSplit || k < n) return weight_lo[k];
  return weight_hi[k - n];
}
#endif

#if PHYXEL_PAIR_ACCESS == 1
void set_nbr_index(uint k, uint j) {
  const uint n = pairs_lo();
  if (!kPairsSplit || k < n) index_lo[k] = j;
  else index_hi[k - n] = j;
}

void set_pair_weight(uint k, float w) {
  const uint n = pairs_lo();
  if (!kPairsSplit || k < n) weight_lo[k] = w;
  else weight_hi[k - n] = w;
}
#endif

#if PHYXEL_PAIR_ACCESS == 2
// The bits of w_ij (0u: severed).
uint pair_weight_bits(uint k) {
  const uint n = pairs_lo();
  if (!kPairsSplit || k < n) return weight_lo[k];
  return weight_hi[k - n];
}

// w_ij of pair slot k as stored (0: a severed or removed pair).
float pair_weight(uint k) {
  return uintBitsToFloat(pair_weight_bits(k));
}

// Sets w_ij to 0 and returns its bits before; atomic, so of two threads severing one pair
// only one sees it nonzero.
uint sever_pair_weight(uint k) {
  const uint n = pairs_lo();
  if (!kPairsSplit || k < n) return atomicExchange(weight_lo[k], 0u);
  return atomicExchange(weight_hi[k - n], 0u);
}

void clear_pair_weight(uint k) {
  const uint n = pairs_lo();
  if (!kPairsSplit || k < n) weight_lo[k] = 0u;
  else weight_hi[k - n] = 0u;
}
#endif

#endif  // PHYXEL_PAIR_BUFFERS_GLSL
