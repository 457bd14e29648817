#pragma once
// The first pass's integrated trace kept for the second (StreamOptions::spill_trace): what
// the second pass reads of each sample, packed — 96 bytes, 120 with a reference channel
// (it was 17 doubles, 136 bytes: the spill's writes are a good part of a long analysis).
// The trigger code is not kept: the second pass does not read it.
#include "dsp/core/spill.hpp"
#include "dsp/pipeline/pipeline.hpp"

#include <cstdint>
#include <memory>
#include <optional>

namespace eical::dsp {

class TraceSpill {
 public:
  // reference: the run has a reference channel (its positions are kept; else NaN on replay).
  TraceSpill(std::unique_ptr<Spill> spill, bool reference) : spill_(std::move(spill)), reference_(reference) {
    if (reference_)
      with_ref_.emplace(*spill_);
    else
      plain_.emplace(*spill_);
  }

  void put(const TraceSample& s) {
    Packed p;
    p.sample_index = s.sample_index;
    p.frame_flags = s.frame_flags;
    p.temp_c[0] = s.temp_c[0], p.temp_c[1] = s.temp_c[1];
    for (int a = 0; a < 3; ++a) p.pos_mm[a] = s.pos_mm[a], p.vel_mm_s[a] = s.vel_mm_s[a], p.cmd_mm[a] = s.cmd_mm[a];
    if (!reference_) {
      plain_->put(p);
      return;
    }
    WithRef r;
    r.p = p;
    for (int a = 0; a < 3; ++a) r.ref_mm[a] = s.ref_mm[a];
    with_ref_->put(r);
  }

  // Every sample as put, in order.
  template <class F>
  void replay(F&& f) {
    TraceSample s;
    s.ref_mm.setConstant(std::numeric_limits<double>::quiet_NaN());
    if (!reference_) {
      plain_->flush();
      for_each_record<Packed>(*spill_, [&](const Packed& p) {
        unpack(p, s);
        f(s);
      });
      return;
    }
    with_ref_->flush();
    for_each_record<WithRef>(*spill_, [&](const WithRef& r) {
      unpack(r.p, s);
      s.ref_mm = {r.ref_mm[0], r.ref_mm[1], r.ref_mm[2]};
      f(s);
    });
  }

 private:
  struct Packed {
    std::int64_t sample_index;
    std::uint32_t frame_flags;
    float temp_c[2];
    double pos_mm[3], vel_mm_s[3], cmd_mm[3];
  };
  struct WithRef {
    Packed p;
    double ref_mm[3];
  };
  static void unpack(const Packed& p, TraceSample& s) {
    s.sample_index = p.sample_index;
    s.frame_flags = p.frame_flags;
    s.temp_c[0] = p.temp_c[0], s.temp_c[1] = p.temp_c[1];
    s.pos_mm = {p.pos_mm[0], p.pos_mm[1], p.pos_mm[2]};
    s.vel_mm_s = {p.vel_mm_s[0], p.vel_mm_s[1], p.vel_mm_s[2]};
    s.cmd_mm = {p.cmd_mm[0], p.cmd_mm[1], p.cmd_mm[2]};
  }
  std::unique_ptr<Spill> spill_;
  bool reference_;
  std::optional<SpillWriter<Packed>> plain_;
  std::optional<SpillWriter<WithRef>> with_ref_;
};

}  // namespace eical::dsp
