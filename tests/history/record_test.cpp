// An eical-result/1 document becomes a history record: every numeric figure with its
// uncertainty (NULL where the result gives none), the verdict when there is one, program
// parameters and pipeline bookkeeping left out, traces thinned, provenance checked.
#include "dsp/core/key_unit.hpp"
#include "history/record/figure_names.hpp"
#include "history/record/record_json.hpp"
#include "history/record/result_record.hpp"
#include "history_support.hpp"

namespace eical::test {
namespace {

using history::Provenance;

Provenance prov() { return {"maho-1", "2026-11-12T10:11:00+01:00", "/var/lib/eical/runs/r1", std::nullopt, ""}; }

TEST(HistoryRecord, FiguresCarryTheirUncertaintyAndNullsStayNull) {
  const auto r = history::record_from_result(circle_result("r1"), prov());
  EXPECT_EQ(r.machine, "maho-1");
  EXPECT_EQ(r.run_id, "r1");
  EXPECT_EQ(r.program, "circle");
  EXPECT_EQ(r.measured_at, "2026-11-12T09:11:00Z");  // +01:00 → UTC
  ASSERT_TRUE(r.verdict);
  EXPECT_EQ(*r.verdict, "ok");
  EXPECT_EQ(r.software_version.value_or(""), "eical 0.1.0");
  EXPECT_EQ(r.sensor_calibration, "datasheet");
  const auto* b = r.figure("diagnostics.backlash_x_um");
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->value.value_or(-1), 6.1);
  EXPECT_EQ(b->uncertainty_k2.value_or(-1), 0.4);
  const auto* f = r.figure("circle.radial_deviation_F_max_um");  // a figure the map gives no U for
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->value.value_or(-1), 3.4);
  EXPECT_FALSE(f->uncertainty_k2);
  const auto* h = r.figure("circle.circular_hysteresis_H_um");  // null in the result: not determined
  ASSERT_NE(h, nullptr);
  EXPECT_FALSE(h->value);
  EXPECT_EQ(r.figure("circle.radius_nominal_mm"), nullptr);  // what the program was asked to do
  EXPECT_EQ(r.figure("circle.revolutions"), nullptr);
  EXPECT_EQ(r.figure("pipeline.rest_window_samples"), nullptr);  // bookkeeping, not a figure
  EXPECT_TRUE(
      std::is_sorted(r.figures.begin(), r.figures.end(), [](const auto& x, const auto& y) { return x.name < y.name; }));
}

TEST(HistoryRecord, ResultsWithoutUncertaintyOrVerdictStoreNulls) {
  CircleFigures f;
  f.uncertainty = false, f.verdict = false;
  const auto r = history::record_from_result(circle_result("r2", f), prov());
  EXPECT_FALSE(r.verdict);
  ASSERT_FALSE(r.figures.empty());
  for (const auto& fig : r.figures) EXPECT_FALSE(fig.uncertainty_k2) << fig.name;
}

TEST(HistoryRecord, TracesAreThinnedForTheStoreWithTheirStride) {
  const auto r = history::record_from_result(circle_result("r3"), prov());
  const auto doc = nlohmann::json::parse(r.document);
  const auto& t = doc["circle"]["trace"];
  EXPECT_LE(t["angle_deg"].size(), history::kStoredTracePoints);
  EXPECT_EQ(t["angle_deg"].size(), t["direction"].size());
  EXPECT_EQ(t["stored_every"], 3);  // 2000 points → every 3rd
  EXPECT_EQ(t["radius_deviation_um"][1], circle_result("r3")["circle"]["trace"]["radius_deviation_um"][3]);
}

TEST(HistoryRecord, BadInputNamesWhatIsWrong) {
  auto doc = circle_result("r4");
  Provenance p = prov();
  p.measured_at = "yesterday";
  try {
    (void)history::record_from_result(doc, p);
    FAIL() << "accepted a time that is not RFC 3339";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("yesterday"), std::string::npos) << e.what();
  }
  doc["format"] = "eical-run/1";
  EXPECT_THROW((void)history::record_from_result(doc, prov()), std::invalid_argument);
  p = prov();
  p.machine.clear();
  EXPECT_THROW((void)history::record_from_result(circle_result("r5"), p), std::invalid_argument);
}

TEST(HistoryRecord, JsonRoundTripIsExact) {
  const auto r = history::record_from_result(circle_result("r6"), prov());
  const auto back = history::record_from_json(nlohmann::json::parse(history::record_json(r).dump()));
  EXPECT_EQ(back.machine, r.machine);
  EXPECT_EQ(back.measured_at, r.measured_at);
  EXPECT_EQ(back.verdict, r.verdict);
  ASSERT_EQ(back.figures.size(), r.figures.size());
  for (std::size_t i = 0; i < r.figures.size(); ++i) {
    EXPECT_EQ(back.figures[i].name, r.figures[i].name);
    EXPECT_EQ(back.figures[i].value, r.figures[i].value);
    EXPECT_EQ(back.figures[i].uncertainty_k2, r.figures[i].uncertainty_k2);
  }
  EXPECT_EQ(nlohmann::json::parse(back.document), nlohmann::json::parse(r.document));
}

TEST(HistoryRecord, NamesSayUnitAndLabel) {
  EXPECT_EQ(dsp::unit_of_key("diagnostics.backlash_x_um"), "µm");
  EXPECT_EQ(dsp::unit_of_key("diagnostics.squareness_urad"), "µrad");
  EXPECT_EQ(dsp::unit_of_key("step.settling_s"), "s");
  EXPECT_EQ(dsp::unit_of_key("circle.feed_mm_min"), "mm/min");
  EXPECT_EQ(dsp::unit_of_key("modes.frequency_hz"), "Hz");
  EXPECT_EQ(dsp::unit_of_key("circle.revolutions"), "");
  EXPECT_EQ(dsp::key_without_unit("circle.feed_mm_min"), "circle.feed");
  EXPECT_EQ(dsp::key_without_unit("step.settling_ms"), "step.settling");
  EXPECT_EQ(dsp::key_without_unit("_um"), "_um");  // a suffix alone names nothing
  EXPECT_EQ(dsp::label_of_key("diagnostics.backlash_x_um"), "backlash X");
  EXPECT_EQ(dsp::label_of_key("circle.circular_deviation_G_um"), "circular deviation G");
  EXPECT_EQ(history::utc_rfc3339("2026-11-12 23:30:00-02:00"), "2026-11-13T01:30:00Z");
  EXPECT_EQ(history::utc_rfc3339("2026-11-12T09:11:00.123Z"), "2026-11-12T09:11:00Z");
  EXPECT_EQ(history::utc_rfc3339("2026-13-12T09:11:00Z"), "");
}

}  // namespace
}  // namespace eical::test
