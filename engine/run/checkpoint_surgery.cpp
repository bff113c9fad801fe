// The surgical state's sections of checkpoint.phx (checkpoint_format.h): written after the run's
// sections 1-8, read back in any order after kTools (the statistics they complete).
#include <array>

#include "engine/run/checkpoint_format.h"

namespace phyxel::checkpoint_format {
namespace {

void read_cut_band(Reader& r, CutBandState& band) {
  const uint64_t n = r.get<uint64_t>();
  for (uint64_t k = 0; k < n; ++k) {
    std::array<Vec3, 4> q;
    for (Vec3& x : q) x = r.get_vec3();
    band.quads.push_back(q);
  }
  band.quads_built = r.get<uint64_t>();
  band.quads_before_chunk = r.get<uint64_t>();
  band.phyxel = r.get_array<uint32_t>();
  band.dirty = r.get_array<uint8_t>();
  band.built_with = r.get_array<uint64_t>();
}

void read_blade_sides(Reader& r, Checkpoint& c) {
  const uint64_t tools = r.get<uint64_t>();
  for (uint64_t t = 0; t < tools; ++t) {
    const uint64_t n = r.get<uint64_t>();
    r.need_items(n, sizeof(uint32_t) + sizeof(uint8_t));  // a corrupt count: refused, not allocated
    std::vector<BladeSide> kept(n);
    for (BladeSide& b : kept) {
      b.phyxel = r.get<uint32_t>();
      b.side = r.get<uint8_t>();
      if (b.side != kSidePlus && b.side != kSideMinus)
        r.corrupt("blade side " + std::to_string(b.side) + " for phyxel " +
                  std::to_string(b.phyxel) + " of tool " + std::to_string(t) + " (sides are " +
                  std::to_string(kSidePlus) + " and " + std::to_string(kSideMinus) + ")");
    }
    c.blade_sides.push_back(std::move(kept));
  }
}

// After kBladeSides: the normal each kept side was learned on, in its order.
void read_side_normals(Reader& r, Checkpoint& c) {
  const uint64_t tools = r.get<uint64_t>();
  if (tools != c.blade_sides.size())
    r.corrupt("side normals for " + std::to_string(tools) + " tools, sides for " +
              std::to_string(c.blade_sides.size()));
  for (std::vector<BladeSide>& kept : c.blade_sides) {
    const std::vector<uint32_t> normals = r.get_array<uint32_t>();
    if (normals.size() != kept.size())
      r.corrupt(std::to_string(normals.size()) + " side normals for " +
                std::to_string(kept.size()) + " sides");
    for (size_t k = 0; k < kept.size(); ++k) kept[k].normal = normals[k];
  }
}

void read_grips(Reader& r, Checkpoint& c) {
  const uint64_t tools = r.get<uint64_t>();
  for (uint64_t t = 0; t < tools; ++t) {
    Grip g;
    g.closed = r.get<uint8_t>() != 0;
    const uint64_t n = r.get<uint64_t>();
    for (uint64_t k = 0; k < n; ++k) {
      GripEntry e;
      e.phyxel = r.get<uint32_t>();
      e.offset = r.get_vec3();
      g.held.push_back(e);
    }
    c.grips.push_back(std::move(g));
  }
}

void read_aspiration(Reader& r, AspiratorState& a) {
  a.log_cursor = r.get<uint64_t>();
  a.removed = r.get_array<uint32_t>();
  a.surface = r.get_array<uint8_t>();
  a.events = r.get<int64_t>();
  a.max_radius = r.get<double>();
  a.removed_mass = r.get_array<double>();
  a.removed_volume = r.get_array<double>();
}

}  // namespace

void write_surgery_sections(Writer& w, const Checkpoint& c) {
  w.begin_section(kCuts);
  w.put<uint64_t>(c.severed.size());
  for (const SeveredPair& p : c.severed) {
    w.put<uint32_t>(p.i);
    w.put<uint32_t>(p.j);
    w.put<float>(p.t);
  }
  w.put<uint64_t>(c.tool_stats.size());
  for (const ToolRunStats& s : c.tool_stats) {
    w.put<double>(s.max_cut_force);
    w.put<int64_t>(s.cutting_substeps);
  }
  w.end_section();

  w.begin_section(kCutFeedback);
  w.put<uint64_t>(c.tool_stats.size());
  for (const ToolRunStats& s : c.tool_stats) {
    w.put<double>(s.max_feedback);
    w.put<double>(s.max_friction);
    w.put<double>(s.max_depth);
  }
  w.end_section();

  w.begin_section(kTorn);
  std::vector<uint8_t> torn(c.severed.size());
  for (size_t k = 0; k < torn.size(); ++k) torn[k] = c.severed[k].torn;
  w.put_array(torn);
  w.end_section();

  w.begin_section(kGrips);
  w.put<uint64_t>(c.grips.size());
  for (const Grip& g : c.grips) {
    w.put<uint8_t>(g.closed ? 1 : 0);
    w.put<uint64_t>(g.held.size());
    for (const GripEntry& e : g.held) {
      w.put<uint32_t>(e.phyxel);
      w.put_vec3(e.offset);
    }
  }
  w.end_section();

  const AspiratorState& a = c.aspiration;
  w.begin_section(kAspiration);
  w.put<uint64_t>(a.log_cursor);
  w.put_array(a.removed);
  w.put_array(a.surface);
  w.put<int64_t>(a.events);
  w.put<double>(a.max_radius);
  w.put_array(a.removed_mass);
  w.put_array(a.removed_volume);
  w.end_section();

  const CutBandState& band = c.band;
  w.begin_section(kCutBand);
  w.put<uint64_t>(band.quads.size());
  for (const auto& q : band.quads)
    for (const Vec3& x : q) w.put_vec3(x);
  w.put<uint64_t>(band.quads_built);
  w.put<uint64_t>(band.quads_before_chunk);
  w.put_array(band.phyxel);
  w.put_array(band.dirty);
  w.put_array(band.built_with);
  w.end_section();

  w.begin_section(kBladeSides);
  w.put<uint64_t>(c.blade_sides.size());
  for (const std::vector<BladeSide>& tool : c.blade_sides) {
    w.put<uint64_t>(tool.size());
    for (const BladeSide& b : tool) {
      w.put<uint32_t>(b.phyxel);
      w.put<uint8_t>(uint8_t(b.side));
    }
  }
  w.end_section();

  w.begin_section(kSideNormals);
  w.put<uint64_t>(c.blade_sides.size());
  for (const std::vector<BladeSide>& tool : c.blade_sides) {
    std::vector<uint32_t> normals;
    for (const BladeSide& b : tool) normals.push_back(b.normal);
    w.put_array(normals);
  }
  w.end_section();

  w.begin_section(kBladeCutting);
  w.put_array(c.blades_cutting);
  w.end_section();
}

void read_surgery_section(Reader& r, uint32_t tag, Checkpoint& c) {
  switch (tag) {
    case kCuts: {  // after kTools (written in that order)
      const uint64_t n = r.get<uint64_t>();
      for (uint64_t k = 0; k < n; ++k) {
        SeveredPair p;
        p.i = r.get<uint32_t>();
        p.j = r.get<uint32_t>();
        p.t = r.get<float>();
        c.severed.push_back(p);
      }
      const uint64_t tools = r.get<uint64_t>();
      for (uint64_t t = 0; t < tools; ++t) {
        const double max_cut = r.get<double>();
        const int64_t cutting = r.get<int64_t>();
        if (t < c.tool_stats.size()) {
          c.tool_stats[t].max_cut_force = max_cut;
          c.tool_stats[t].cutting_substeps = cutting;
        }
      }
      break;
    }
    case kCutFeedback: {  // after kTools
      const uint64_t tools = r.get<uint64_t>();
      for (uint64_t t = 0; t < tools; ++t) {
        const double feedback = r.get<double>(), friction = r.get<double>(),
                     depth = r.get<double>();
        if (t < c.tool_stats.size()) {
          c.tool_stats[t].max_feedback = feedback;
          c.tool_stats[t].max_friction = friction;
          c.tool_stats[t].max_depth = depth;
        }
      }
      break;
    }
    case kTorn: {  // after kCuts
      const std::vector<uint8_t> torn = r.get_array<uint8_t>();
      if (torn.size() != c.severed.size())
        r.corrupt(std::to_string(torn.size()) + " torn flags for " +
                  std::to_string(c.severed.size()) + " severed pairs (one flag each)");
      for (size_t k = 0; k < torn.size(); ++k) c.severed[k].torn = torn[k] != 0;
      break;
    }
    case kGrips:
      read_grips(r, c);
      break;
    case kAspiration:
      read_aspiration(r, c.aspiration);
      break;
    case kCutBand:
      read_cut_band(r, c.band);
      break;
    case kBladeSides:
      read_blade_sides(r, c);
      break;
    case kSideNormals:  // after kBladeSides
      read_side_normals(r, c);
      break;
    case kBladeCutting:
      c.blades_cutting = r.get_array<uint8_t>();
      for (size_t t = 0; t < c.blades_cutting.size(); ++t)
        if (c.blades_cutting[t] > 1)
          r.corrupt("cutting state " + std::to_string(c.blades_cutting[t]) + " for tool " +
                    std::to_string(t) + " (0 or 1)");
      break;
    default:  // a section this version does not know: skipped
      break;
  }
}

}  // namespace phyxel::checkpoint_format
