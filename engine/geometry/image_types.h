// Internal to image_volume*.cpp: NIfTI data type codes <-> VoxelType, and typed access to a
// volume's stored values.
#pragma once

#include <nifti1.h>

#include <cstdint>
#include <optional>
#include <type_traits>

#include "engine/geometry/image_volume.h"

namespace phyxel {

inline std::optional<VoxelType> voxel_type_of(int datatype) {
  switch (datatype) {
    case DT_UINT8:
      return VoxelType::UInt8;
    case DT_INT8:
      return VoxelType::Int8;
    case DT_INT16:
      return VoxelType::Int16;
    case DT_UINT16:
      return VoxelType::UInt16;
    case DT_INT32:
      return VoxelType::Int32;
    case DT_UINT32:
      return VoxelType::UInt32;
    case DT_INT64:
      return VoxelType::Int64;
    case DT_UINT64:
      return VoxelType::UInt64;
    case DT_FLOAT32:
      return VoxelType::Float32;
    case DT_FLOAT64:
      return VoxelType::Float64;
  }
  return std::nullopt;
}

inline int nifti_datatype(VoxelType type) {
  switch (type) {
    case VoxelType::UInt8:
      return DT_UINT8;
    case VoxelType::Int8:
      return DT_INT8;
    case VoxelType::Int16:
      return DT_INT16;
    case VoxelType::UInt16:
      return DT_UINT16;
    case VoxelType::Int32:
      return DT_INT32;
    case VoxelType::UInt32:
      return DT_UINT32;
    case VoxelType::Int64:
      return DT_INT64;
    case VoxelType::UInt64:
      return DT_UINT64;
    case VoxelType::Float32:
      return DT_FLOAT32;
    case VoxelType::Float64:
      return DT_FLOAT64;
  }
  return DT_UNKNOWN;
}

// Calls f(const T* values) with the volume's bytes as its stored type T.
template <class Bytes, class F>
void with_typed(VoxelType type, Bytes* bytes, F&& f) {
  constexpr bool kConst = std::is_const_v<Bytes>;
  auto as = [&](auto tag) {
    using T = decltype(tag);
    using P = std::conditional_t<kConst, const T*, T*>;
    f(reinterpret_cast<P>(bytes));
  };
  switch (type) {
    case VoxelType::UInt8:
      return as(uint8_t{});
    case VoxelType::Int8:
      return as(int8_t{});
    case VoxelType::Int16:
      return as(int16_t{});
    case VoxelType::UInt16:
      return as(uint16_t{});
    case VoxelType::Int32:
      return as(int32_t{});
    case VoxelType::UInt32:
      return as(uint32_t{});
    case VoxelType::Int64:
      return as(int64_t{});
    case VoxelType::UInt64:
      return as(uint64_t{});
    case VoxelType::Float32:
      return as(float{});
    case VoxelType::Float64:
      return as(double{});
  }
}

template <class F>
void with_voxel_values(const ImageVolume& volume, F&& f) {
  with_typed(volume.type, volume.bytes.data(), f);
}

}  // namespace phyxel
