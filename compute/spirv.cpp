#include "compute/spirv.h"

#include <algorithm>
#include <tuple>

namespace phyxel::gpu {
namespace {

constexpr uint32_t kSpirvMagic = 0x07230203;
constexpr uint32_t kMaxIdBound = 1u << 22;  // far beyond any shader here; guards the tables

// Opcodes, decorations, storage classes and dimensions of the SPIR-V specification.
constexpr uint32_t kOpName = 5;
constexpr uint32_t kOpExecutionMode = 16;
constexpr uint32_t kOpTypeImage = 25;
constexpr uint32_t kOpTypeSampler = 26;
constexpr uint32_t kOpTypeSampledImage = 27;
constexpr uint32_t kOpTypeArray = 28;
constexpr uint32_t kOpTypeRuntimeArray = 29;
constexpr uint32_t kOpTypeStruct = 30;
constexpr uint32_t kOpTypePointer = 32;
constexpr uint32_t kOpConstant = 43;
constexpr uint32_t kOpSpecConstant = 50;
constexpr uint32_t kOpVariable = 59;
constexpr uint32_t kOpDecorate = 71;
constexpr uint32_t kOpExecutionModeId = 331;
constexpr uint32_t kOpTypeAccelerationStructure = 5341;
constexpr uint32_t kDecorationBlock = 2;
constexpr uint32_t kDecorationBufferBlock = 3;
constexpr uint32_t kDecorationBinding = 33;
constexpr uint32_t kDecorationDescriptorSet = 34;
constexpr uint32_t kModeLocalSize = 17;
constexpr uint32_t kModeLocalSizeId = 38;
constexpr uint32_t kStorageUniformConstant = 0;
constexpr uint32_t kStorageUniform = 2;
constexpr uint32_t kStorageBuffer = 12;
constexpr uint32_t kDimBuffer = 5;
constexpr uint32_t kDimSubpassData = 6;

VulkanError shader_error(const ShaderCode& code, const std::string& what) {
  return VulkanError("shader '" + std::string(code.name) + "': " + what);
}

// The module's words after the header, checked to be SPIR-V.
size_t checked_word_count(const ShaderCode& code) {
  if (code.words == nullptr || code.bytes < 20 || code.bytes % 4 != 0 ||
      code.words[0] != kSpirvMagic) {
    throw shader_error(code, "not SPIR-V");
  }
  return code.bytes / 4;
}

// Where each id is defined and what is said of it: enough to follow a variable to its type.
class Module {
 public:
  explicit Module(const ShaderCode& code) : code_(code), count_(checked_word_count(code)) {
    const uint32_t bound = code.words[3];
    if (bound > kMaxIdBound) throw shader_error(code, "id bound " + std::to_string(bound));
    def_.assign(bound, 0);
    names_.resize(bound);
    set_.assign(bound, 0);
    binding_.assign(bound, kNone);
    buffer_block_.assign(bound, false);
    for (size_t i = 5; i < count_;) {
      const uint32_t words = code.words[i] >> 16;
      if (words == 0 || i + words > count_) throw shader_error(code, "truncated instruction");
      read(i, words);
      i += words;
    }
  }

  std::vector<SpirvBinding> bindings() const {
    std::vector<SpirvBinding> out;
    for (const size_t at : variables_) {
      const uint32_t id = word(at + 2);
      if (binding_[id] == kNone) continue;
      SpirvBinding b;
      b.set = set_[id];
      b.binding = binding_[id];
      describe(id, word(at + 3), pointee(word(at + 1)), b);
      out.push_back(std::move(b));
    }
    std::sort(out.begin(), out.end(), [](const SpirvBinding& a, const SpirvBinding& b) {
      return std::tie(a.set, a.binding) < std::tie(b.set, b.binding);
    });
    return out;
  }

 private:
  static constexpr uint32_t kNone = ~0u;

  uint32_t word(size_t at) const { return code_.words[at]; }
  uint32_t opcode(size_t at) const { return word(at) & 0xffffu; }

  uint32_t checked_id(uint32_t id) const {
    if (id >= def_.size()) throw shader_error(code_, "id " + std::to_string(id) + " out of bound");
    return id;
  }

  // The instruction that defines `id` (a type or constant).
  size_t definition(uint32_t id) const {
    const size_t at = def_[checked_id(id)];
    if (at == 0) throw shader_error(code_, "id " + std::to_string(id) + " is not defined");
    return at;
  }

  void read(size_t at, uint32_t words) {
    const uint32_t op = opcode(at);
    if (op == kOpName && words >= 3) {
      names_[checked_id(word(at + 1))] = literal(at + 2, at + words);
    } else if (op == kOpDecorate && words >= 3) {
      const uint32_t id = checked_id(word(at + 1));
      const uint32_t decoration = word(at + 2);
      if (decoration == kDecorationBinding && words >= 4) binding_[id] = word(at + 3);
      if (decoration == kDecorationDescriptorSet && words >= 4) set_[id] = word(at + 3);
      if (decoration == kDecorationBufferBlock) buffer_block_[id] = true;
    } else if (op == kOpVariable && words >= 4) {
      def_[checked_id(word(at + 2))] = at;
      variables_.push_back(at);
    } else if ((op == kOpConstant || op == kOpSpecConstant) && words >= 4) {
      def_[checked_id(word(at + 2))] = at;
    } else if (op >= kOpTypeImage && op <= kOpTypePointer && words >= 2) {
      def_[checked_id(word(at + 1))] = at;
    } else if (op == kOpTypeAccelerationStructure && words >= 2) {
      def_[checked_id(word(at + 1))] = at;
    }
  }

  std::string literal(size_t from, size_t end) const {
    std::string s;
    for (size_t i = from; i < end; ++i) {
      for (int byte = 0; byte < 4; ++byte) {
        const char c = static_cast<char>((word(i) >> (8 * byte)) & 0xffu);
        if (c == '\0') return s;
        s += c;
      }
    }
    return s;
  }

  uint32_t pointee(uint32_t pointer_type) const {
    const size_t at = definition(pointer_type);
    if (opcode(at) != kOpTypePointer || (word(at) >> 16) < 4) {
      throw shader_error(code_, "variable " + std::to_string(pointer_type) + " is not a pointer");
    }
    return word(at + 3);
  }

  // Fills the type, count and name of the variable `id` of `storage` class and `type`.
  void describe(uint32_t id, uint32_t storage, uint32_t type, SpirvBinding& b) const {
    size_t at = definition(type);
    while (opcode(at) == kOpTypeArray || opcode(at) == kOpTypeRuntimeArray) {
      if (opcode(at) == kOpTypeRuntimeArray) {
        b.count = 0;
      } else {
        const size_t length = definition(word(at + 3));
        if ((word(length) >> 16) < 4) throw shader_error(code_, "array length is not a constant");
        b.count *= word(length + 3);
      }
      at = definition(word(at + 2));
    }
    const uint32_t base = word(at + 1);
    b.name = opcode(at) == kOpTypeStruct && !names_[base].empty() ? names_[base] : names_[id];
    b.type = descriptor_type(storage, at, b);
  }

  VkDescriptorType descriptor_type(uint32_t storage, size_t at, const SpirvBinding& b) const {
    const uint32_t op = opcode(at);
    if (storage == kStorageBuffer) return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    if (storage == kStorageUniform) {
      return buffer_block_[word(at + 1)] ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER
                                         : VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    }
    if (storage == kStorageUniformConstant) {
      if (op == kOpTypeSampler) return VK_DESCRIPTOR_TYPE_SAMPLER;
      if (op == kOpTypeAccelerationStructure) return VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
      if (op == kOpTypeSampledImage) {
        const size_t image = definition(word(at + 2));
        return word(image + 3) == kDimBuffer ? VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER
                                             : VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
      }
      if (op == kOpTypeImage && (word(at) >> 16) >= 9) {
        const uint32_t dim = word(at + 3);
        const bool storage_image = word(at + 7) == 2;
        if (dim == kDimSubpassData) return VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT;
        if (dim == kDimBuffer) {
          return storage_image ? VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER
                               : VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
        }
        return storage_image ? VK_DESCRIPTOR_TYPE_STORAGE_IMAGE : VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
      }
    }
    throw shader_error(code_, "binding " + std::to_string(b.binding) + " ('" + b.name +
                                  "') has no descriptor type (storage class " +
                                  std::to_string(storage) + ", type opcode " + std::to_string(op) +
                                  ")");
  }

  const ShaderCode& code_;
  size_t count_;
  std::vector<size_t> def_;  // id -> word offset of its defining instruction (0: none)
  std::vector<std::string> names_;
  std::vector<uint32_t> set_, binding_;
  std::vector<bool> buffer_block_;
  std::vector<size_t> variables_;
};

std::string where(const SpirvBinding& b) {
  return "set " + std::to_string(b.set) + " binding " + std::to_string(b.binding);
}

std::string kind(const SpirvBinding& b) {
  std::string s = descriptor_type_name(b.type);
  if (b.count != 1) s += b.count == 0 ? " (runtime array)" : " [" + std::to_string(b.count) + "]";
  return s;
}

// "set 0: 0-12 storage buffer; set 1: 0 combined image sampler" (runs of one kind merged).
std::string summary(const std::vector<SpirvBinding>& list) {
  if (list.empty()) return "no bindings";
  std::string s;
  for (size_t i = 0; i < list.size();) {
    size_t j = i + 1;
    while (j < list.size() && list[j].set == list[i].set &&
           list[j].binding == list[j - 1].binding + 1 && kind(list[j]) == kind(list[i])) {
      ++j;
    }
    if (!s.empty()) s.append("; ");
    if (i == 0 || list[i - 1].set != list[i].set) {
      s.append("set ").append(std::to_string(list[i].set)).append(": ");
    }
    s.append(std::to_string(list[i].binding));
    if (j - i > 1) s.append("-").append(std::to_string(list[j - 1].binding));
    s.append(" ").append(kind(list[i]));
    i = j;
  }
  return s;
}

const SpirvBinding* find(const std::vector<SpirvBinding>& list, const SpirvBinding& b) {
  for (const SpirvBinding& x : list)
    if (x.set == b.set && x.binding == b.binding) return &x;
  return nullptr;
}

}  // namespace

std::array<uint32_t, 3> spirv_workgroup_size(const ShaderCode& code) {
  const size_t count = checked_word_count(code);
  for (size_t i = 5; i < count;) {
    const uint32_t words = code.words[i] >> 16;
    const uint32_t opcode = code.words[i] & 0xffffu;
    if (words == 0 || i + words > count) break;
    if (opcode == kOpExecutionMode && words >= 6 && code.words[i + 2] == kModeLocalSize) {
      return {code.words[i + 3], code.words[i + 4], code.words[i + 5]};
    }
    if ((opcode == kOpExecutionMode || opcode == kOpExecutionModeId) && words >= 3 &&
        code.words[i + 2] == kModeLocalSizeId) {
      break;
    }
    i += words;
  }
  throw shader_error(code,
                     "no literal local_size (specialization-constant workgroup sizes are not "
                     "supported by dispatch())");
}

std::vector<SpirvBinding> spirv_bindings(const ShaderCode& code) {
  return Module(code).bindings();
}

void check_bindings(const ShaderCode& code, const std::vector<SpirvBinding>& shader,
                    const std::vector<SpirvBinding>& declared) {
  std::vector<SpirvBinding> code_side = declared;
  std::sort(code_side.begin(), code_side.end(), [](const SpirvBinding& a, const SpirvBinding& b) {
    return std::tie(a.set, a.binding) < std::tie(b.set, b.binding);
  });
  const std::string sides =
      " (shader: " + summary(shader) + "; code declares: " + summary(code_side) + ")";
  for (const SpirvBinding& s : shader) {
    const SpirvBinding* c = find(code_side, s);
    const std::string what = where(s) + " ('" + s.name + "')";
    if (c == nullptr) {
      throw shader_error(code, what + " is a " + kind(s) +
                                   " in the SPIR-V but missing from the layout the code "
                                   "declares" +
                                   sides);
    }
    if (c->type != s.type || c->count != s.count) {
      throw shader_error(code, what + " is a " + kind(s) + " in the SPIR-V but a " + kind(*c) +
                                   " in the layout the code declares" + sides);
    }
  }
  for (const SpirvBinding& c : code_side) {
    if (find(shader, c) == nullptr) {
      throw shader_error(code, "the code declares " + where(c) + " (" + kind(c) +
                                   ") but the SPIR-V has no such binding" + sides);
    }
  }
}

std::string descriptor_type_name(VkDescriptorType type) {
  switch (type) {
    case VK_DESCRIPTOR_TYPE_SAMPLER:
      return "sampler";
    case VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER:
      return "combined image sampler";
    case VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE:
      return "sampled image";
    case VK_DESCRIPTOR_TYPE_STORAGE_IMAGE:
      return "storage image";
    case VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER:
      return "uniform texel buffer";
    case VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER:
      return "storage texel buffer";
    case VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER:
      return "uniform buffer";
    case VK_DESCRIPTOR_TYPE_STORAGE_BUFFER:
      return "storage buffer";
    case VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT:
      return "input attachment";
    case VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR:
      return "acceleration structure";
    default:
      return "descriptor type " + std::to_string(static_cast<int>(type));
  }
}

}  // namespace phyxel::gpu
