// eical history add | list | show | trend | compare: the calibration history of a machine
// or a shop's fleet (history/store). --db is a SQLite file (default: eicald's
// /var/lib/eical/history.db) or a PostgreSQL URI; $EICAL_HISTORY_DB sets it for a session.
#include "history/query/compare.hpp"
#include "history/query/trend_stats.hpp"
#include "history/record/figure_names.hpp"
#include "history/record/record_json.hpp"
#include "history/sql/pg_connection.hpp"
#include "history/store/store.hpp"
#include "tools/commands.hpp"
#include "tools/history/history_format.hpp"
#include "tools/history/run_record.hpp"
#include "tools/report/history_pages.hpp"

#include <cstdio>
#include <memory>
#include <stdexcept>

namespace eical::tools {
namespace {

namespace hv = history_view;
constexpr const char* kDefaultDb = "/var/lib/eical/history.db";

struct Opt {
  std::string db = kDefaultDb;
  bool json = false;
  std::vector<std::string> runs;
  std::string machine, calibration, program, since, until, figure, run, before, after, html;
  std::size_t limit = 0;
};

void add_db(CLI::App* c, Opt& o) {
  c->add_option("--db", o.db, "history store: a SQLite file or postgresql://user@host/db")
      ->envname("EICAL_HISTORY_DB")
      ->default_val(kDefaultDb);
  c->add_flag("--json", o.json, "print JSON (eical-history-*/1) instead of text");
}

void add_filter(CLI::App* c, Opt& o) {
  c->add_option("--machine", o.machine, "only this machine ([machine] name)");
  c->add_option("--program", o.program, "only this program: circle, step, positioning, rectangle, freeform");
  c->add_option("--since", o.since, "measured at or after this UTC time (RFC 3339 or a prefix: 2026-11, 2026-11-12)");
  c->add_option("--until", o.until, "measured before this UTC time (same forms)");
  c->add_option("--limit", o.limit, "only the newest N results");
}

// A full date-time (any offset) is compared as stored, in UTC; a shorter text as a prefix.
std::string utc_or_prefix(const std::string& t) {
  const std::string utc = history::utc_rfc3339(t);
  return utc.empty() ? t : utc;
}

history::Filter filter_of(const Opt& o) {
  return {o.machine, o.program, utc_or_prefix(o.since), utc_or_prefix(o.until), o.limit};
}

std::unique_ptr<history::Store> open_store(const Opt& o, bool create = false) {
  return history::Store::open(o.db, {.create = create});
}

void print(const std::string& text) { std::fputs(text.c_str(), stdout); }
void print(const nlohmann::json& j) { std::printf("%s\n", j.dump(2).c_str()); }

// "RUN" or "RUN@MACHINE": exactly one stored result, else an error naming the candidates.
history::Record one_result(history::Store& s, const std::string& spec, const std::string& machine_option) {
  std::string run = spec, machine = machine_option;
  if (const auto at = spec.rfind('@'); at != std::string::npos && at > 0)
    run = spec.substr(0, at), machine = spec.substr(at + 1);
  auto found = s.find(run, machine);
  if (found.empty())
    throw std::runtime_error("history: no result " + run + (machine.empty() ? "" : " of machine " + machine) + " in " +
                             s.location() + " (eical history list shows what is there)");
  if (found.size() > 1) {
    std::string names;
    for (const auto& r : found) names += (names.empty() ? "" : ", ") + r.machine;
    throw std::runtime_error("history: run " + run + " is stored for several machines (" + names +
                             "): say which, e.g. " + run + "@" + found[0].machine);
  }
  return std::move(found[0]);
}

void check_figure(history::Store& s, const std::string& figure, const std::string& machine) {
  const auto names = s.figure_names(machine);
  if (std::find(names.begin(), names.end(), figure) != names.end()) return;
  std::string known;
  for (std::size_t i = 0; i < names.size() && i < 12; ++i) known += (i ? ", " : "") + names[i];
  if (names.size() > 12) known += ", ...";
  throw std::runtime_error("history: no figure " + figure + (machine.empty() ? "" : " for machine " + machine) +
                           " in " + s.location() +
                           (names.empty() ? " (no results)" : "; figures are named <section>.<key>, e.g. " + known));
}

void cmd_add(const Opt& o) {
  auto store = open_store(o, /*create=*/true);
  nlohmann::json out = {{"format", "eical-history-add/1"},
                        {"added", nlohmann::json::array()},
                        {"already_stored", nlohmann::json::array()},
                        {"failed", nlohmann::json::array()}};
  std::size_t failed = 0;
  for (const auto& run : o.runs) {
    try {
      const auto r = run_record(run, {o.machine, o.calibration});
      const bool added = store->add(r) == history::AddOutcome::added;
      out[added ? "added" : "already_stored"].push_back(
          {{"machine", r.machine}, {"run_id", r.run_id}, {"run_path", r.run_path}});
      if (!o.json)
        std::printf("%s %s %s (%s, %s UTC, verdict %s)\n", added ? "added" : "already stored:", r.machine.c_str(),
                    r.run_id.c_str(), r.program.c_str(), hv::when(r.measured_at).c_str(),
                    r.verdict.value_or("-").c_str());
    } catch (const std::exception& e) {
      ++failed;
      out["failed"].push_back({{"run", run}, {"error", e.what()}});
      std::fprintf(stderr, "eical: history add %s: %s\n", run.c_str(), e.what());
    }
  }
  if (o.json) print(out);
  if (failed) throw CLI::RuntimeError(1);
}

void cmd_list(const Opt& o) {
  auto store = open_store(o);
  const auto rows = store->list(filter_of(o));
  if (o.json)
    print(hv::list_json(history::sql::redact_uri(o.db), rows));
  else
    print(hv::list_text(rows));
}

void cmd_show(const Opt& o) {
  auto store = open_store(o);
  const auto r = one_result(*store, o.run, o.machine);
  if (o.json) {
    nlohmann::json j = {{"format", "eical-history-record/1"}};
    j.update(history::record_json(r));
    print(j);
  } else {
    print(hv::record_text(r));
  }
}

void cmd_trend(const Opt& o) {
  auto store = open_store(o);
  check_figure(*store, o.figure, o.machine);
  const auto points = store->trend(o.figure, filter_of(o));
  const auto summaries = history::summarize(points);
  if (!o.html.empty())
    report::write_html(report::trend_page(o.figure, points, summaries, history::sql::redact_uri(o.db)), o.html);
  if (o.json)
    print(hv::trend_json(o.figure, points, summaries));
  else
    print(hv::trend_text(o.figure, points, summaries) + (o.html.empty() ? "" : "trend plot: " + o.html + "\n"));
}

void cmd_compare(const Opt& o) {
  auto store = open_store(o);
  const auto before = one_result(*store, o.before, o.machine);
  const auto after = one_result(*store, o.after, o.machine);
  const auto c = history::compare(before, after);
  if (!o.html.empty()) {
    std::vector<std::pair<std::string, std::vector<history::TrendPoint>>> trends;
    for (const auto& f : c.figures)
      if (f.judgement == history::Judgement::significant)
        trends.emplace_back(f.name, store->trend(f.name, {.machine = after.machine}));
    report::write_html(report::compare_page(c, before, after, trends, history::sql::redact_uri(o.db)), o.html);
  }
  if (o.json)
    print(hv::compare_json(c));
  else
    print(hv::compare_text(c) + (o.html.empty() ? "" : "report: " + o.html + "\n"));
}

}  // namespace

void register_history(CLI::App& app) {
  auto o = std::make_shared<Opt>();
  auto* h = app.add_subcommand("history", "Calibration history: results of a machine or a fleet, trends, comparisons");
  h->require_subcommand(1);

  auto* add = h->add_subcommand("add", "Add recorded runs (their result.json, or analysed now) to the history");
  add->add_option("runs", o->runs, "run directories (eical-run/1)")->required()->check(CLI::ExistingDirectory);
  add->add_option("--machine", o->machine, "machine name (default: run.toml's [machine] name)");
  add->add_option("--calibration", o->calibration, "analyse with this sensor calibration (eical-sensor-cal/1)")
      ->check(CLI::ExistingFile);
  add_db(add, *o);
  add->callback([o] { cmd_add(*o); });

  auto* list = h->add_subcommand("list", "List stored results, oldest first");
  add_filter(list, *o);
  add_db(list, *o);
  list->callback([o] { cmd_list(*o); });

  auto* show = h->add_subcommand("show", "One result: provenance and every figure with its uncertainty");
  show->add_option("run", o->run, "run id, or RUN@MACHINE when several machines have it")->required();
  show->add_option("--machine", o->machine, "the machine of the run");
  add_db(show, *o);
  show->callback([o] { cmd_show(*o); });

  auto* trend = h->add_subcommand("trend", "One figure over time with its uncertainty, and each machine's drift");
  trend->add_option("figure", o->figure, "<section>.<key> of eical-result/1, e.g. diagnostics.backlash_x_um")
      ->required();
  add_filter(trend, *o);
  trend->add_option("--html", o->html, "also write the trend plot as a self-contained HTML page");
  add_db(trend, *o);
  trend->callback([o] { cmd_trend(*o); });

  auto* cmp =
      h->add_subcommand("compare", "Two results figure by figure: difference, combined uncertainty, significance");
  cmp->add_option("before", o->before, "run id (or RUN@MACHINE) of the earlier result")->required();
  cmp->add_option("after", o->after, "run id (or RUN@MACHINE) of the later result")->required();
  cmp->add_option("--machine", o->machine, "the machine of both runs");
  cmp->add_option("--html", o->html,
                  "also write an HTML page: polar plots overlaid, every figure, trends of the changed ones");
  add_db(cmp, *o);
  cmp->callback([o] { cmd_compare(*o); });
}

}  // namespace eical::tools
