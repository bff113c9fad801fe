#include "engine/run/vtp_writer.h"

#include <charconv>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/run/atomic_file.h"

namespace phyxel {
namespace {

// One data array: its XML attributes and its values as raw bytes.
struct Array {
  std::string name;  // empty for Points
  const char* type;
  int components;
  std::string bytes;
};

template <class T>
void append_raw(std::string& bytes, const T& value) {
  bytes.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

Array vec_array(const std::string& name, const PhyxelSet& set, auto&& value) {
  Array a{name, "Float64", 3, {}};
  a.bytes.reserve(set.size() * 24);
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3 v = value(i);
    for (int c = 0; c < 3; ++c) append_raw(a.bytes, v[c]);
  }
  return a;
}

// Values as `out << value` writes them at the stream's precision (17 significant digits for
// doubles, %g style: they read back exactly), formatted by std::to_chars into a buffer written
// in large pieces: the points file of a 1M-phyxel run is tens of millions of numbers.
void write_ascii_values(std::ostream& out, const Array& a) {
  const bool is_double = std::strcmp(a.type, "Float64") == 0;
  const size_t width = std::strcmp(a.type, "UInt32") == 0 ? 4 : 8;
  const size_t count = a.bytes.size() / width;
  const size_t per_line = 3 * static_cast<size_t>(a.components);
  std::string text;
  text.reserve(1 << 20);
  char number[64];
  for (size_t k = 0; k < count; ++k) {
    const char* p = a.bytes.data() + k * width;
    std::to_chars_result r{};
    if (is_double) {
      double d;
      std::memcpy(&d, p, 8);
      r = std::to_chars(number, number + sizeof number, d, std::chars_format::general,
                        static_cast<int>(out.precision()));
    } else if (width == 8) {
      int64_t v;
      std::memcpy(&v, p, 8);
      r = std::to_chars(number, number + sizeof number, v);
    } else {
      uint32_t v;
      std::memcpy(&v, p, 4);
      r = std::to_chars(number, number + sizeof number, v);
    }
    text.append(number, r.ptr);
    text.push_back((k + 1) % per_line == 0 ? '\n' : ' ');
    if (text.size() > (1 << 20) - 128) {
      out.write(text.data(), static_cast<std::streamsize>(text.size()));
      text.clear();
    }
  }
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
}

void write_array(std::ostream& out, const Array& a, bool binary, uint64_t& offset) {
  out << "<DataArray type=\"" << a.type << "\"";
  if (!a.name.empty()) out << " Name=\"" << a.name << "\"";
  out << " NumberOfComponents=\"" << a.components << "\"";
  if (binary) {
    out << " format=\"appended\" offset=\"" << offset << "\"/>\n";
    offset += sizeof(uint64_t) + a.bytes.size();
    return;
  }
  out << " format=\"ascii\">\n";
  write_ascii_values(out, a);
  out << "\n</DataArray>\n";
}

}  // namespace

void write_points_vtp(const std::filesystem::path& file, const PhyxelSet& set,
                      const PointState& state, bool binary) {
  const size_t n = set.size();
  Array points =
      vec_array("", set, [&](size_t i) { return Vec3(set.rest[i] + state.displacement[i]); });
  std::vector<Array> data;
  data.push_back(vec_array("rest_position", set, [&](size_t i) { return set.rest[i]; }));
  data.push_back(vec_array("displacement", set, [&](size_t i) { return state.displacement[i]; }));
  data.push_back(vec_array("velocity", set, [&](size_t i) { return state.velocity[i]; }));
  Array vm{"von_mises", "Float64", 1, {}};
  for (size_t i = 0; i < n; ++i)
    append_raw(vm.bytes, state.von_mises.empty() ? 0.0 : state.von_mises[i]);
  data.push_back(std::move(vm));
  Array flags{"flags", "UInt32", 1, {}};
  for (size_t i = 0; i < n; ++i) append_raw(flags.bytes, set.flags[i]);
  data.push_back(std::move(flags));
  if (!state.max_principal_stress.empty()) {  // scenes that can tear: Pa
    Array sigma{"max_principal_stress", "Float64", 1, {}};
    for (size_t i = 0; i < n; ++i) append_raw(sigma.bytes, state.max_principal_stress[i]);
    data.push_back(std::move(sigma));
  }
  if (!state.contact.empty()) {  // scenes with tools: 1 where a tool touched the phyxel
    Array contact{"contact", "UInt32", 1, {}};
    for (size_t i = 0; i < n; ++i) append_raw(contact.bytes, uint32_t{state.contact[i]});
    data.push_back(std::move(contact));
  }
  Array connectivity{"connectivity", "Int64", 1, {}}, offsets{"offsets", "Int64", 1, {}};
  for (size_t i = 0; i < n; ++i) {
    append_raw(connectivity.bytes, static_cast<int64_t>(i));
    append_raw(offsets.bytes, static_cast<int64_t>(i + 1));
  }

  std::ostringstream xml;
  xml.precision(17);
  xml << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n<PolyData>\n<Piece NumberOfPoints=\""
      << n << "\" NumberOfVerts=\"" << n
      << "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n";
  uint64_t offset = 0;
  xml << "<Points>\n";
  write_array(xml, points, binary, offset);
  xml << "</Points>\n<PointData Vectors=\"displacement\" Scalars=\"von_mises\">\n";
  for (const Array& a : data) write_array(xml, a, binary, offset);
  xml << "</PointData>\n<Verts>\n";
  write_array(xml, connectivity, binary, offset);
  write_array(xml, offsets, binary, offset);
  xml << "</Verts>\n</Piece>\n</PolyData>\n";
  if (binary) {
    xml << "<AppendedData encoding=\"raw\">\n_";
    // Every block in the order of the offsets above: the points, each data array (the
    // `max_principal_stress` and `contact` arrays included when there are), the connectivity
    // and the offsets.
    std::vector<const Array*> blocks{&points};
    for (const Array& a : data) blocks.push_back(&a);
    blocks.push_back(&connectivity);
    blocks.push_back(&offsets);
    for (const Array* a : blocks) {
      const uint64_t size = a->bytes.size();
      xml.write(reinterpret_cast<const char*>(&size), sizeof size);
      xml.write(a->bytes.data(), static_cast<std::streamsize>(a->bytes.size()));
    }
    xml << "\n</AppendedData>\n";
  }
  xml << "</VTKFile>\n";

  write_file_atomically(file, xml.str());
}

}  // namespace phyxel
