#pragma once
// The DAQ's sampling rate when nothing has told one yet: the thesis' 10 kHz, at which the
// drivers acquire both triplexes and the PSD lock-in channels. Every option struct that
// needs a rate before a run (or the daemon's config) tells it starts from this one value;
// a run's own rate (run.toml [acquisition] fs_hz) always wins.
namespace eical::dsp {

inline constexpr double kDefaultFs_hz = 10000.0;

}  // namespace eical::dsp
