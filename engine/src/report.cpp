#include "dovetail/engine/report.h"

#include <unistd.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "dovetail/engine/json.h"
#include "dovetail/engine/scene.h"

namespace dovetail::engine {

namespace {

std::string number(double value) { return json_number(value); }

std::string hex(std::uint64_t value) {
  char buffer[24];
  std::snprintf(buffer, sizeof(buffer), "0x%016llx", static_cast<unsigned long long>(value));
  return buffer;
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.flush();
  if (!out) throw std::runtime_error(path.string() + ": cannot be written");
}

double seconds_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

void StateHasher::add(std::string_view name, const collision::Transform& X_WP) {
  // Eight bytes a word, the first in the lowest byte, zero-padded (a name of
  // a multiple of eight bytes ends with a zero word).
  for (std::size_t i = 0; i <= name.size(); i += 8) {
    const std::size_t take = std::min<std::size_t>(8, name.size() - i);
    std::uint64_t w = 0;
    if constexpr (std::endian::native == std::endian::little) {
      std::memcpy(&w, name.data() + i, take);
    } else {
      for (std::size_t k = 0; k < take; ++k) {
        w |= std::uint64_t{static_cast<unsigned char>(name[i + k])} << (8 * k);
      }
    }
    word(w);
  }
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) word(std::bit_cast<std::uint64_t>(X_WP.R(r, c)));
  }
  for (int k = 0; k < 3; ++k) word(std::bit_cast<std::uint64_t>(X_WP.t(k)));
}

std::uint64_t state_hash(const Scene& scene) {
  StateHasher hasher;
  for (const PartId part : scene.parts()) hasher.add(scene.name(part), scene.world_pose(part));
  return hasher.value();
}

std::string Report::timings_json() const {
  std::vector<double> totals;
  double collision_sum = 0, total_sum = 0;
  for (const FrameTiming& t : timings) {
    totals.push_back(t.total_ms);
    collision_sum += t.collision_ms;
    total_sum += t.total_ms;
  }
  std::sort(totals.begin(), totals.end());
  const double median = totals.empty() ? 0 : totals[totals.size() / 2];
  std::string out = "{\n    \"frames\": " + std::to_string(timings.size()) +
                    ",\n    \"total_ms\": " + number(total_sum) +
                    ",\n    \"collision_ms\": " + number(collision_sum) +
                    ",\n    \"frame_ms_median\": " + number(median) + ",\n    \"per_frame\": [";
  for (std::size_t i = 0; i < timings.size(); ++i) {
    out += i == 0 ? "\n      " : ",\n      ";
    out += "{\"frame\": " + std::to_string(i) +
           ", \"collision_ms\": " + number(timings[i].collision_ms) +
           ", \"total_ms\": " + number(timings[i].total_ms) + "}";
  }
  out += timings.empty() ? "]\n  }" : "\n    ]\n  }";
  return out;
}

std::string Report::to_json(bool with_timings) const {
  std::string out = "{\n";
  out += "  \"format\": \"dovetail-report\",\n";
  out += "  \"version\": 1,\n";
  out += "  \"time_step\": " + number(time_step) + ",\n";
  out += "  \"frames\": " + std::to_string(frames) + ",\n";
  out += "  \"time\": " + number(static_cast<double>(frames) * time_step) + ",\n";
  out += "  \"parts\": " + std::to_string(parts) + ",\n";
  // No frame, no state to hash: null, never a hash of nothing that could pass for one.
  out += "  \"state_hash\": " + (frames > 0 ? "\"" + hex(state_hash) + "\"" : std::string("null")) +
         ",\n";
  out += "  \"events\": [";
  for (std::size_t i = 0; i < events.size(); ++i) {
    const Event& e = events[i];
    out += i == 0 ? "\n    " : ",\n    ";
    out += "{\"frame\": " + std::to_string(e.frame) + ", \"time\": " + number(e.time) +
           ", \"kind\": " + json_string(std::string(event_kind_name(e.kind))) +
           ", \"a\": " + json_string(e.a);
    if (!e.b.empty()) out += ", \"b\": " + json_string(e.b);
    out += "}";
  }
  out += events.empty() ? "],\n" : "\n  ],\n";
  out += "  \"contacts\": [";
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const PairContactStats& c = contacts[i];
    out += i == 0 ? "\n    " : ",\n    ";
    out += "{\"a\": " + json_string(c.a) + ", \"b\": " + json_string(c.b) +
           ", \"frames_in_contact\": " + std::to_string(c.frames_in_contact) +
           ", \"first_frame\": " + std::to_string(c.first_frame) +
           ", \"last_frame\": " + std::to_string(c.last_frame) +
           ", \"max_contacts\": " + std::to_string(c.max_contacts) + "}";
  }
  out += contacts.empty() ? "]" : "\n  ]";
  out += ",\n  \"collision_plans\": [";
  for (std::size_t i = 0; i < plans.size(); ++i) {
    const PairPlanReport& p = plans[i];
    out += i == 0 ? "\n    " : ",\n    ";
    out += "{\"a\": " + json_string(p.a) + ", \"b\": " + json_string(p.b) +
           ", \"level\": " + json_string(p.level);
    if (!p.method.empty()) out += ", \"method\": " + json_string(p.method);
    out += std::string(", \"convex_level\": ") + (p.convex_level ? "true" : "false") +
           ", \"front\": " + (p.front ? "true" : "false");
    if (p.max_size > 0) out += ", \"max_size\": " + number(p.max_size);
    out += ", \"reason\": " + json_string(p.reason) + "}";
  }
  out += plans.empty() ? "]" : "\n  ]";
  if (!notes.empty()) {
    out += ",\n  \"notes\": [";
    for (std::size_t i = 0; i < notes.size(); ++i) {
      out += (i == 0 ? "\n    " : ",\n    ") + json_string(notes[i]);
    }
    out += "\n  ]";
  }
  if (with_timings) out += ",\n  \"timings\": " + timings_json();
  out += "\n}\n";
  return out;
}

void Report::write_json(const std::filesystem::path& path, bool with_timings) const {
  write_text(path, to_json(with_timings));
}

void Report::write_timings_json(const std::filesystem::path& path) const {
  write_text(path, "{\n  \"timings\": " + timings_json() + "\n}\n");
}

ProgressMeter::ProgressMeter(std::uint64_t total, std::FILE* out)
    : total_(total),
      out_(out != nullptr ? out : stderr),
      terminal_(isatty(fileno(out_)) != 0),
      start_s_(seconds_now()) {}

void ProgressMeter::update(std::uint64_t done) {
  if (terminal_) {
    const int percent = total_ == 0 ? 100 : static_cast<int>(done * 100 / total_);
    if (percent == last_percent_) return;
    last_percent_ = percent;
    constexpr int kWidth = 40;
    const int filled = percent * kWidth / 100;
    std::fprintf(out_, "\r[%s%s] %3d%% frame %llu/%llu", std::string(filled, '#').c_str(),
                 std::string(kWidth - filled, ' ').c_str(), percent,
                 static_cast<unsigned long long>(done), static_cast<unsigned long long>(total_));
    std::fflush(out_);
    return;
  }
  constexpr double kEverySeconds = 5.0;
  const double now = seconds_now();
  if (last_print_s_ < 0) last_print_s_ = start_s_;
  if (now - last_print_s_ < kEverySeconds) return;
  last_print_s_ = now;
  std::fprintf(out_, "frame %llu/%llu\n", static_cast<unsigned long long>(done),
               static_cast<unsigned long long>(total_));
  std::fflush(out_);
}

void ProgressMeter::finish() {
  if (terminal_) {
    last_percent_ = -1;
    update(total_);
    std::fputc('\n', out_);
  } else {
    std::fprintf(out_, "frame %llu/%llu done\n", static_cast<unsigned long long>(total_),
                 static_cast<unsigned long long>(total_));
  }
  std::fflush(out_);
}

}  // namespace dovetail::engine
