#include "drivers/dds/bus.hpp"

#include "drivers/dds/idl_convert.hpp"

#include <dds/dds.h>

#include <cstring>
#include <vector>

namespace eical::drivers::dds {
namespace {

void check(dds_return_t rc, const char* what) {
  if (rc < 0) throw BusError(std::string("dds: ") + what + ": " + dds_strretcode(rc));
}

dds_entity_t checked(dds_entity_t e, const char* what) {
  check(e, what);
  return e;
}

// Strings in the generated types are char*; the writer only reads them during dds_write.
char* cs(const std::string& s) { return const_cast<char*>(s.c_str()); }
std::string str(const char* s) { return s ? std::string(s) : std::string(); }

struct QosDeleter {
  void operator()(dds_qos_t* q) const { dds_delete_qos(q); }
};
using Qos = std::unique_ptr<dds_qos_t, QosDeleter>;

Qos qos(bool reliable, bool transient_local, int32_t depth) {
  Qos q(dds_create_qos());
  if (reliable)
    dds_qset_reliability(q.get(), DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  else
    dds_qset_reliability(q.get(), DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_durability(q.get(), transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  dds_qset_history(q.get(), DDS_HISTORY_KEEP_LAST, depth);
  return q;
}

struct Endpoint {
  dds_entity_t topic = 0, writer = 0, reader = 0, waitset = 0;
};

}  // namespace

struct Bus::Impl {
  dds_entity_t participant = 0, guard = 0;
  Endpoint status, live, result, trace, command, reply;

  void make(Endpoint& ep, const dds_topic_descriptor_t* desc, const char* name, const Qos& q, bool write, bool read) {
    ep.topic = checked(dds_create_topic(participant, desc, name, nullptr, nullptr), name);
    if (write) ep.writer = checked(dds_create_writer(participant, ep.topic, q.get(), nullptr), "create writer");
    if (read) {
      ep.reader = checked(dds_create_reader(participant, ep.topic, q.get(), nullptr), "create reader");
      ep.waitset = checked(dds_create_waitset(participant), "create waitset");
      const dds_entity_t rc = checked(dds_create_readcondition(ep.reader, DDS_ANY_STATE), "create read condition");
      check(dds_waitset_attach(ep.waitset, rc, ep.reader), "attach read condition");
      check(dds_waitset_attach(ep.waitset, guard, 0), "attach guard condition");
    }
  }

  // Waits for data on ep, takes one valid sample into `out` via `copy`.
  template <class C, class Copy>
  bool take_one(Endpoint& ep, std::chrono::milliseconds timeout, Copy&& copy) {
    const dds_return_t n = dds_waitset_wait(ep.waitset, nullptr, 0, DDS_MSECS(timeout.count()));
    if (n <= 0) return false;
    (void)dds_set_guardcondition(guard, false);
    void* samples[1] = {nullptr};
    dds_sample_info_t info[1];
    const dds_return_t got = dds_take(ep.reader, samples, info, 1, 1);
    if (got <= 0) return false;
    const bool valid = info[0].valid_data;
    if (valid) copy(*static_cast<const C*>(samples[0]));
    (void)dds_return_loan(ep.reader, samples, got);
    return valid;
  }
};

Bus::Bus(int domain_id, Role role) : impl_(std::make_unique<Impl>()) {
  auto& d = *impl_;
  d.participant = dds_create_participant(static_cast<dds_domainid_t>(domain_id), nullptr, nullptr);
  if (d.participant < 0)
    throw BusError(std::string("dds: cannot create a participant on domain ") + std::to_string(domain_id) + ": " +
                   dds_strretcode(d.participant) + " (check CYCLONEDDS_URI)");
  d.guard = checked(dds_create_guardcondition(d.participant), "create guard condition");
  const bool daemon = role == Role::daemon;
  d.make(d.status, &eical_msg_Status_desc, "eical_Status", qos(true, false, 1), daemon, !daemon);
  d.make(d.live, &eical_msg_Live_desc, "eical_Live", qos(false, false, 8), daemon, !daemon);
  d.make(d.result, &eical_msg_Result_desc, "eical_Result", qos(true, true, 1), daemon, !daemon);
  d.make(d.trace, &eical_msg_Trace_desc, "eical_Trace", qos(true, true, 1), daemon, !daemon);
  d.make(d.command, &eical_msg_Command_desc, "eical_Command", qos(true, false, 16), !daemon, daemon);
  d.make(d.reply, &eical_msg_Reply_desc, "eical_Reply", qos(true, false, 16), daemon, !daemon);
}

Bus::~Bus() {
  if (impl_ && impl_->participant > 0) (void)dds_delete(impl_->participant);  // deletes every child entity
}

bool Bus::publish(const StatusMsg& m) {
  eical_msg_Status s{};
  s.daemon = cs(m.daemon), s.state = cs(m.state), s.fault = cs(m.fault);
  s.frames = m.frames, s.overruns = m.overruns, s.frames_lost = m.frames_lost, s.measurements = m.measurements,
  s.results = m.results;
  s.temp_table_c = m.temp_table_c, s.temp_head_c = m.temp_head_c, s.time_ns = m.time_ns;
  s.sample_index = m.sample_index, s.sample_time_ns = m.sample_time_ns;
  copy_counters(s, m.counters);
  const bool ok = impl_->status.writer > 0 && dds_write(impl_->status.writer, &s) >= 0;
  if (!ok) write_errors_.fetch_add(1, std::memory_order_relaxed);
  return ok;
}

bool Bus::publish(const LiveMsg& m) {
  eical_msg_Live s{};
  s.daemon = cs(m.daemon);
  s.sample_index = m.sample_index;
  for (int i = 0; i < 3; ++i)
    s.pos_mm[i] = m.pos_mm[static_cast<std::size_t>(i)], s.vel_mm_s[i] = m.vel_mm_s[static_cast<std::size_t>(i)];
  s.integrating = m.integrating;
  s.acquired_ns = m.acquired_ns;
  const bool ok = impl_->live.writer > 0 && dds_write(impl_->live.writer, &s) >= 0;
  if (!ok) write_errors_.fetch_add(1, std::memory_order_relaxed);
  return ok;
}

bool Bus::publish(const ResultMsg& m) {
  eical_msg_Result s{};
  s.machine = cs(m.machine), s.program_id = cs(m.program_id), s.program = cs(m.program), s.json = cs(m.json);
  s.measured_at = cs(m.measured_at), s.run_path = cs(m.run_path), s.software_version = cs(m.software_version);
  s.sensor_calibration = cs(m.sensor_calibration);
  s.degraded = m.degraded;
  s.circular_deviation_G_um = m.circular_deviation_G_um, s.radius_mean_deviation_um = m.radius_mean_deviation_um;
  s.results = m.results;
  const bool ok = impl_->result.writer > 0 && dds_write(impl_->result.writer, &s) >= 0;
  if (!ok) write_errors_.fetch_add(1, std::memory_order_relaxed);
  return ok;
}

bool Bus::publish(const TraceMsg& m) {
  eical_msg_Trace s{};
  s.program_id = cs(m.program_id), s.program = cs(m.program), s.x_name = cs(m.x_name), s.y_name = cs(m.y_name);
  // The sequences borrow the vectors' storage for the write (dds_write only reads it);
  // vector<bool> has no contiguous storage, so the directions are unpacked once.
  std::unique_ptr<bool[]> cw(new bool[m.cw.size() + 1]);
  for (std::size_t i = 0; i < m.cw.size(); ++i) cw[i] = m.cw[i];
  s.x._length = s.x._maximum = static_cast<uint32_t>(m.x.size()), s.x._buffer = const_cast<double*>(m.x.data());
  s.y._length = s.y._maximum = static_cast<uint32_t>(m.y.size()), s.y._buffer = const_cast<double*>(m.y.data());
  s.series._length = s.series._maximum = static_cast<uint32_t>(m.series.size()),
  s.series._buffer = const_cast<std::int32_t*>(m.series.data());
  s.cw._length = s.cw._maximum = static_cast<uint32_t>(m.cw.size()), s.cw._buffer = cw.get();
  s.decimation = m.decimation;
  const bool ok = impl_->trace.writer > 0 && dds_write(impl_->trace.writer, &s) >= 0;
  if (!ok) write_errors_.fetch_add(1, std::memory_order_relaxed);
  return ok;
}

bool Bus::publish(const ReplyMsg& m) {
  eical_msg_Reply s{};
  s.sender = cs(m.sender), s.message = cs(m.message), s.state = cs(m.state);
  s.request_id = m.request_id, s.ok = m.ok;
  const bool ok = impl_->reply.writer > 0 && dds_write(impl_->reply.writer, &s) >= 0;
  if (!ok) write_errors_.fetch_add(1, std::memory_order_relaxed);
  return ok;
}

bool Bus::send(const CommandMsg& m) {
  eical_msg_Command s{};
  s.sender = cs(m.sender), s.action = cs(m.action);
  s.request_id = m.request_id, s.code = m.code, s.p = m.p, s.q = m.q, s.time_ns = m.time_ns;
  const bool ok = impl_->command.writer > 0 && dds_write(impl_->command.writer, &s) >= 0;
  if (!ok) write_errors_.fetch_add(1, std::memory_order_relaxed);
  return ok;
}

std::optional<StatusMsg> Bus::take_status(std::chrono::milliseconds timeout) {
  if (impl_->status.reader <= 0) return std::nullopt;
  StatusMsg out;
  const bool ok = impl_->take_one<eical_msg_Status>(impl_->status, timeout, [&](const eical_msg_Status& s) {
    out = {str(s.daemon), str(s.state),   str(s.fault),  s.frames,  s.overruns,     s.frames_lost,    s.measurements,
           s.results,     s.temp_table_c, s.temp_head_c, s.time_ns, s.sample_index, s.sample_time_ns, {}};
    copy_counters(out.counters, s);
  });
  return ok ? std::optional(out) : std::nullopt;
}

std::optional<LiveMsg> Bus::take_live(std::chrono::milliseconds timeout) {
  if (impl_->live.reader <= 0) return std::nullopt;
  LiveMsg out;
  const bool ok = impl_->take_one<eical_msg_Live>(impl_->live, timeout, [&](const eical_msg_Live& s) {
    out.daemon = str(s.daemon);
    out.sample_index = s.sample_index;
    for (std::size_t i = 0; i < 3; ++i) out.pos_mm[i] = s.pos_mm[i], out.vel_mm_s[i] = s.vel_mm_s[i];
    out.integrating = s.integrating;
    out.acquired_ns = s.acquired_ns;
  });
  return ok ? std::optional(out) : std::nullopt;
}

std::optional<ResultMsg> Bus::take_result(std::chrono::milliseconds timeout) {
  if (impl_->result.reader <= 0) return std::nullopt;
  ResultMsg out;
  const bool ok = impl_->take_one<eical_msg_Result>(impl_->result, timeout, [&](const eical_msg_Result& s) {
    out = {str(s.machine),
           str(s.program_id),
           str(s.program),
           s.degraded,
           s.circular_deviation_G_um,
           s.radius_mean_deviation_um,
           s.results,
           str(s.json),
           str(s.measured_at),
           str(s.run_path),
           str(s.software_version),
           str(s.sensor_calibration)};
  });
  return ok ? std::optional(out) : std::nullopt;
}

std::optional<TraceMsg> Bus::take_trace(std::chrono::milliseconds timeout) {
  if (impl_->trace.reader <= 0) return std::nullopt;
  TraceMsg out;
  const bool ok = impl_->take_one<eical_msg_Trace>(impl_->trace, timeout, [&](const eical_msg_Trace& s) {
    out.program_id = str(s.program_id), out.program = str(s.program), out.x_name = str(s.x_name),
    out.y_name = str(s.y_name);
    out.x.assign(s.x._buffer, s.x._buffer + s.x._length);
    out.y.assign(s.y._buffer, s.y._buffer + s.y._length);
    out.series.assign(s.series._buffer, s.series._buffer + s.series._length);
    out.cw.assign(s.cw._buffer, s.cw._buffer + s.cw._length);
    out.decimation = s.decimation;
  });
  return ok ? std::optional(out) : std::nullopt;
}

std::optional<CommandMsg> Bus::take_command(std::chrono::milliseconds timeout) {
  if (impl_->command.reader <= 0) return std::nullopt;
  CommandMsg out;
  const bool ok = impl_->take_one<eical_msg_Command>(impl_->command, timeout,
                                                     [&](const eical_msg_Command& s) { out = from_idl(s); });
  return ok ? std::optional(out) : std::nullopt;
}

std::optional<ReplyMsg> Bus::take_reply(std::chrono::milliseconds timeout) {
  if (impl_->reply.reader <= 0) return std::nullopt;
  ReplyMsg out;
  const bool ok = impl_->take_one<eical_msg_Reply>(impl_->reply, timeout, [&](const eical_msg_Reply& s) {
    out = {str(s.sender), s.request_id, s.ok, str(s.message), str(s.state)};
  });
  return ok ? std::optional(out) : std::nullopt;
}

void Bus::wake() { (void)dds_set_guardcondition(impl_->guard, true); }

int Bus::matched_result_readers() const {
  if (impl_->result.writer <= 0) return 0;
  dds_publication_matched_status_t st{};
  if (dds_get_publication_matched_status(impl_->result.writer, &st) < 0) return 0;
  return static_cast<int>(st.current_count);
}

}  // namespace eical::drivers::dds
