// The evaluation workflow (io/evaluation.h) and `pushgraph evaluate`: tables from a small
// simulated set, shards merged bit-identically, failed trajectories counted, clear errors for bad
// options; one real MIT recording when the shared data is present.
#include <pushgraph/evaluation/evaluation.h>
#include <pushgraph/io/trajectory_json.h>

#include "test_scale.h"
#include "tool_runner.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace pushgraph::evaluation {
namespace {

namespace fs = std::filesystem;

const std::string kData = std::string(PUSHGRAPH_SOURCE_DIR) + "/data/shapes/";
const std::string kMit = std::string(PUSHGRAPH_SHARED_DIR) + "/data/mit-push/";

EvaluationOptions SmallSimulatedSet(int count, const std::string& protocols) {
  EvaluationOptions o;
  o.protocols = ParseProtocols(protocols);
  o.simulation.count = count;
  o.simulation.name = "sim:notched_block";
  o.simulation.object.shape = geometry::LoadShapeJson(kData + "notched_block.json");
  o.simulation.finger.shape = geometry::LoadShapeJson(kData + "disk_finger_5mm.json");
  o.simulation.object.mass = 0.5;
  o.simulation.object.mu_surface = 0.3;
  o.simulation.finger.mu_contact = 0.4;
  o.simulation.push_distance = 0.03;  // short pushes keep the test fast
  o.seed = 5;
  return o;
}

const Table* Find(const std::vector<Table>& tables, const std::string& id) {
  for (const Table& t : tables) {
    if (t.id == id) return &t;
  }
  return nullptr;
}

double Cell(const Table& t, const std::string& quantity, const std::string& column) {
  const auto col = std::find(t.columns.begin(), t.columns.end(), column) - t.columns.begin();
  for (const auto& r : t.rows) {
    if (r[2] == quantity) return std::stod(r[col]);
  }
  ADD_FAILURE() << "no row '" << quantity << "' in " << t.id;
  return 0.0;
}

class Evaluation : public testing::ToolTest {};

TEST_F(Evaluation, ProtocolsAndShardsAreParsedWithClearErrors) {
  EXPECT_EQ(ParseProtocols("all").size(), 6u);
  const std::vector<Protocol> p = ParseProtocols("fig5, table1,fig5");
  ASSERT_EQ(p.size(), 2u);  // canonical order, no duplicates
  EXPECT_EQ(p[0], Protocol::kTable1);
  EXPECT_EQ(p[1], Protocol::kFig5);
  try {
    ParseProtocols("table1,tabel2");
    FAIL();
  } catch (const EvaluationError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown protocol 'tabel2'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ParseProtocols(""), EvaluationError);
  EXPECT_EQ(ParseShard("3/8"), std::make_pair(3, 8));
  for (const char* bad : {"8/8", "1/0", "-1/4", "1", "a/b", "1/2/3"}) EXPECT_THROW(ParseShard(bad), EvaluationError) << bad;
}

TEST_F(Evaluation, InputsExpandFoldersAndGlobsAndNameMissingOnes) {
  fs::create_directories(dir_ / "in" / "sub");
  Write("in/b.json", "{}");
  Write("in/sub/a.h5", "x");
  Write("in/notes.txt", "x");
  const std::vector<std::string> files = ExpandInputs({(dir_ / "in").string(), (dir_ / "in" / "*.json").string()});
  ASSERT_EQ(files.size(), 2u);  // sorted, without duplicates, only .h5/.hdf5/.json
  EXPECT_NE(files[0].find("b.json"), std::string::npos);
  EXPECT_NE(files[1].find("sub/a.h5"), std::string::npos);
  try {
    ExpandInputs({(dir_ / "missing.h5").string()});
    FAIL();
  } catch (const EvaluationError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.h5"), std::string::npos);
  }
  EXPECT_THROW(ExpandInputs({(dir_ / "in" / "*.nothing").string()}), EvaluationError);
}

TEST_F(Evaluation, InputKindIsDecidedByContent) {
  EXPECT_EQ(DetectInputKind(Write("mit.json", R"({"tip_pose": [], "object_pose": [], "ft_wrench": []})")),
            InputKind::kMitRecording);
  EXPECT_EQ(DetectInputKind(Write("h5.bin", std::string("\x89HDF\r\n\x1a\n", 8) + "rest")), InputKind::kMitRecording);
  push::Trajectory t;
  t.object.shape = geometry::Shape::Disk(0.05);
  t.finger.shape = geometry::Shape::Disk(0.005);
  t.object.mass = 0.5;
  io::SaveTrajectoryJson(t, (dir_ / "traj.json").string());
  EXPECT_EQ(DetectInputKind((dir_ / "traj.json").string()), InputKind::kTrajectory);
  for (const std::string& bad : {Write("other.json", R"({"format": "something-else"})"), Write("list.json", "[1, 2]"),
                                 Write("text.json", "not json")}) {
    try {
      DetectInputKind(bad);
      FAIL() << bad;
    } catch (const EvaluationError& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

TEST_F(Evaluation, AddedNoiseKeepsTheCleanStreamsAsGroundTruth) {
  EvaluationOptions o = SmallSimulatedSet(1, "table1");
  const push::Trajectory clean = SimulatedPush(o.simulation, 0, 5);
  ASSERT_TRUE(clean.ground_truth);
  const push::Trajectory noisy = AddNoise(clean, MakePaperNoise(push::NoiseKind::kGaussian), 9);
  ASSERT_TRUE(noisy.measurement_sigmas);
  EXPECT_EQ(noisy.measurement_sigmas->object_trans, 0.005);
  EXPECT_EQ(noisy.measurement_sigmas->object_rot, 0.05);
  EXPECT_EQ(noisy.measurement_sigmas->force, 0.5);
  EXPECT_EQ(noisy.ground_truth->object_pose.size(), clean.ground_truth->object_pose.size());
  EXPECT_EQ(noisy.ground_truth->object_pose[3].pose.x, clean.ground_truth->object_pose[3].pose.x);
  EXPECT_NE(noisy.measured.object_pose[3].pose.x, clean.ground_truth->object_pose[3].pose.x);
  // Same seed, same noise; the simulated pushes differ from each other.
  EXPECT_EQ(AddNoise(clean, MakePaperNoise(push::NoiseKind::kGaussian), 9).measured.force[5].force,
            noisy.measured.force[5].force);
  EXPECT_NE(SimulatedPush(o.simulation, 1, 5).ground_truth->finger_pose.back().pose.x,
            clean.ground_truth->finger_pose.back().pose.x);
}

// The multi-contact group's flat pusher (push 3 at seed 1, as in docs/results.md): its face
// settles flat onto the notched block's face across the notch. With the simulator's earlier
// 0.1 um contact tolerance the contact flipped from one end of the 64 mm face to the other at
// every 4 ms step (63 changes of the contact set; 2 now), and the line contact's incremental
// covariances then failed as rank deficient and were left out of the tables without a word.
TEST_F(Evaluation, AFlatPushersLineContactIsSimulatedAndEstimatedWithCovariances) {
  EvaluationOptions o;
  o.protocols = ParseProtocols("fig5,consistency");  // every model, batch and incremental, with covariances
  o.multi_contact_simulation.count = 4;
  o.multi_contact_simulation.name = "sim-multi:notched_block";
  o.multi_contact_simulation.multi_contact = true;
  o.multi_contact_simulation.object.shape = geometry::LoadShapeJson(kData + "notched_block.json");
  o.multi_contact_simulation.object.mass = 0.5;
  o.multi_contact_simulation.object.mu_surface = 0.3;
  o.multi_contact_simulation.finger = {geometry::LoadShapeJson(kData + "disk_finger_5mm.json"), 0.4};
  o.seed = 1;
  ASSERT_EQ(MultiContactPushKindOf(3), MultiContactPushKind::kFlatPusher);
  const push::Trajectory clean = SimulatedPush(o.multi_contact_simulation, 3, o.seed);
  std::map<double, int> rows_at;
  for (const push::PointSample& c : clean.ground_truth->contact_point) ++rows_at[c.t];
  int changes = 0, previous = 0, line_contact_steps = 0;
  for (const auto& [t, rows] : rows_at) {
    changes += rows != previous;
    previous = rows;
    line_contact_steps += rows >= 2;
  }
  EXPECT_LE(changes, 3);  // no contact, one corner, then the line contact (its four end points)
  EXPECT_GT(line_contact_steps, 100);
  // Eight estimates with covariances: 22 s here, 6 minutes under the sanitizers, which run the
  // same code in the main stage's other estimator tests.
  if (pushgraph::testing::TestScale() < 1.0) return;
  EvaluationItem item;
  for (const EvaluationItem& i : PlanEvaluation({}, o))
    if (i.multi_contact_sim && i.sim_index == 3) item = i;
  ASSERT_EQ(item.sim_index, 3);
  const std::vector<EvaluationRow> rows = RunEvaluation({item}, o, 2);
  ASSERT_EQ(rows.size(), 1u);
  ASSERT_TRUE(rows[0].error.empty()) << rows[0].error;
  for (const std::string& note : rows[0].notes) EXPECT_EQ(note.find("no covariances"), std::string::npos) << note;
  for (const char* run : {"gauss.qs.batch", "gauss.qs.incremental", "gauss.cp.incremental"}) {
    const auto n = rows[0].stats.find(std::string(run) + "/object_pose/nees_n");
    ASSERT_NE(n, rows[0].stats.end()) << run;
    EXPECT_GT(n->second, 200) << run;
  }
  // The bar lies across the V: its line contact's inner rows (the V's corners) place the object
  // along the face (OverlapEndMeasurementFactor). Object-pose NEES (dimension 3) QS batch 11.7
  // and incremental 5.7, CP 3.1; with the outer rows only 25.7, 22.5 and 6.7.
  auto nees = [&](const std::string& run) {
    return rows[0].stats.at(run + "/object_pose/nees") / rows[0].stats.at(run + "/object_pose/nees_n");
  };
  EXPECT_LT(nees("gauss.qs.batch"), 16.0);
  EXPECT_LT(nees("gauss.qs.incremental"), 10.0);
  EXPECT_LT(nees("gauss.cp.batch"), 5.0);
}

// Pictures: the first plots_per_group items of each group get a Fig. 3/5 and an occlusion SVG
// with every model's error curve; the others none.
TEST_F(Evaluation, PicturesOfTheFirstPushOfEachGroup) {
  EvaluationOptions o = SmallSimulatedSet(2, "fig5,occlusion");
  o.plot_dir = (dir_ / "plots").string();
  const std::vector<EvaluationItem> items = PlanEvaluation({}, o);
  ASSERT_EQ(items.size(), 2u);
  EXPECT_TRUE(items[0].plot);
  EXPECT_FALSE(items[1].plot);
  for (const EvaluationItem& item : items) {
    const EvaluationRow row = EvaluateItem(item, o);
    EXPECT_TRUE(row.error.empty()) << row.error;
  }
  for (const char* name : {"sim_notched_block-0-fig3.svg", "sim_notched_block-0-occlusion.svg"}) {
    std::ifstream in(dir_ / "plots" / name);
    ASSERT_TRUE(in) << name;
    const std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(svg.find("<svg"), std::string::npos) << name;
    for (const char* label : {"raw", "CP", "SDF", "QS", "Yu-Rodriguez"}) {
      EXPECT_NE(svg.find(std::string(">") + label + "<"), std::string::npos) << name << " lacks " << label;
    }
  }
  EXPECT_FALSE(fs::exists(dir_ / "plots" / "sim_notched_block-1-fig3.svg"));
}

// One evaluation of three short simulated pushes and a broken file: the tables have the
// expected rows, estimates beat the raw measurements, the broken file is counted, and the rows
// of two shards merge into exactly the same tables.
TEST_F(Evaluation, TablesFromSimulatedPushesAndShardsMergeBitIdentically) {
  EvaluationOptions o = SmallSimulatedSet(3, "table1,table2");
  const std::string broken = Write("broken.json", "{\"format\": \"pushgraph-trajectory-1\", \"object\": 3}");
  const std::vector<EvaluationItem> items = PlanEvaluation({broken}, o);
  ASSERT_EQ(items.size(), 4u);
  const std::vector<EvaluationRow> rows = RunEvaluation(items, o, 2);
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_NE(rows[0].error.find("broken.json"), std::string::npos) << rows[0].error;
  for (int i = 1; i < 4; ++i) EXPECT_TRUE(rows[i].error.empty()) << rows[i].error;

  const std::vector<Table> tables = MakeTables(rows, o.SettingsJson());
  const Table* t1 = Find(tables, "table1");
  const Table* t2 = Find(tables, "table2");
  ASSERT_TRUE(t1 && t2);
  EXPECT_EQ(Find(tables, "fig5"), nullptr);
  EXPECT_LT(Cell(*t1, "object position (moving)", "RMS"), Cell(*t1, "object position (moving)", "raw RMS"));
  EXPECT_LT(Cell(*t1, "contact point", "RMS"), Cell(*t1, "contact point", "raw RMS"));
  EXPECT_LT(Cell(*t1, "force", "RMS"), Cell(*t1, "force", "raw RMS"));
  EXPECT_GT(Cell(*t1, "force", "1-sigma"), 0.0);
  EXPECT_LT(Cell(*t2, "contact location", "RMSE"), Cell(*t2, "contact location", "raw RMSE"));
  EXPECT_GT(Cell(*t2, "force direction", "samples"), 100.0);
  bool noted = false;
  for (const std::string& n : t1->notes) noted = noted || n.find("1 trajectories failed") != std::string::npos;
  EXPECT_TRUE(noted);

  // Shards 0/2 and 1/2, each evaluated on its own and written/read through rows files.
  std::vector<std::string> shard_files;
  for (int k = 0; k < 2; ++k) {
    const std::vector<EvaluationItem> part = ShardItems(items, k, 2);
    ASSERT_EQ(part.size(), 2u);
    const std::string path = (dir_ / ("rows-" + std::to_string(k) + ".jsonl")).string();
    WriteRows(path, {k, 2, static_cast<int>(items.size()), o.SettingsJson()}, RunEvaluation(part, o, 1));
    shard_files.push_back(path);
  }
  RowsHeader header;
  const std::vector<EvaluationRow> merged = MergeRows({shard_files[1], shard_files[0]}, &header);
  ASSERT_EQ(merged.size(), rows.size());
  const std::vector<Table> merged_tables = MakeTables(merged, header.settings_json);
  ASSERT_EQ(merged_tables.size(), tables.size());
  for (std::size_t i = 0; i < tables.size(); ++i) {
    EXPECT_EQ(TableMarkdown(merged_tables[i]), TableMarkdown(tables[i]));
    EXPECT_EQ(TableCsv(merged_tables[i]), TableCsv(tables[i]));
  }
  // Every statistic but the solve times (which differ from run to run) and the covariance-derived
  // ones (last bits, below) is bit-identical; the tables above are identical.
  auto without_times = [](std::map<std::string, double> stats) {
    for (auto it = stats.begin(); it != stats.end();) {
      it = it->first.find("time/") != std::string::npos ? stats.erase(it) : std::next(it);
    }
    return stats;
  };
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto a = without_times(merged[i].stats), b = without_times(rows[i].stats);
    EXPECT_EQ(a.size(), b.size()) << "row " << i;
    for (const auto& [key, value] : a) {
      const auto it = b.find(key);
      if (it == b.end()) {
        ADD_FAILURE() << "row " << i << ": " << key << " only in the merged shards";
      } else if (key.find("/var") != std::string::npos || key.find("/nees") != std::string::npos) {
        // Covariance-derived: ceres::Covariance's sparse QR can round differently from one run to
        // the next (measured: up to 1e-15 relative, the estimates themselves bit-identical).
        EXPECT_NEAR(it->second, value, 1e-12 * std::abs(value)) << "row " << i << ": " << key;
      } else if (!(it->second == value)) {  // bit-identical, not approximately equal
        ADD_FAILURE() << "row " << i << ": " << key << " merged " << value << " unsharded " << it->second;
      }
    }
  }

  // Merging checks that the shards belong together.
  try {
    MergeRows({shard_files[0]}, &header);
    FAIL();
  } catch (const EvaluationError& e) {
    EXPECT_NE(std::string(e.what()).find("shard 1/2 is missing"), std::string::npos) << e.what();
  }
  EXPECT_THROW(MergeRows({shard_files[0], shard_files[0]}, &header), EvaluationError);
  EvaluationOptions other = o;
  other.seed = 6;
  const std::string foreign = (dir_ / "foreign.jsonl").string();
  WriteRows(foreign, {1, 2, 4, other.SettingsJson()}, {});
  EXPECT_THROW(MergeRows({shard_files[0], foreign}, &header), EvaluationError);
  EXPECT_THROW(ReadRows(Write("garbage.jsonl", "{\"a\": 1}\n"), &header), EvaluationError);
  // Appended rows, the last one cut by a kill: dropped when asked (a resume), an error otherwise.
  const std::string appended = (dir_ / "appended.jsonl").string();
  WriteRows(appended, {0, 1, 3, "{}"}, {});
  EvaluationRow row;
  row.index = 1;
  row.name = "sim-0001";
  row.group = "sim";
  AppendRow(appended, row);
  std::ofstream(appended, std::ios::app) << "{\"index\": 2, \"na";
  EXPECT_EQ(ReadRows(appended, &header, /*cut_last_line_ok=*/true).size(), 1u);
  EXPECT_THROW(ReadRows(appended, &header), EvaluationError);
}

// A push too short for any judged factor type to reach 20 degrees of freedom has no score: "n/a",
// after the scored rows, left out of the group's median (it ranked as the healthiest, score 0,
// and pulled the median to 0).
TEST_F(Evaluation, APushTooShortToScoreIsNotRankedOrCounted) {
  EvaluationOptions o;
  o.protocols = ParseProtocols("fig5");
  std::vector<EvaluationRow> rows(4);
  const char* names[] = {"short", "good", "bad", "short2"};
  const double health[] = {0.0, 1.2, 3.0, 0.0};
  const char* worst[] = {"", "object_pose", "force", ""};
  for (int i = 0; i < 4; ++i) {
    rows[i].index = i;
    rows[i].name = names[i];
    rows[i].group = "g";
    rows[i].steps = 10;
    rows[i].health = health[i];
    rows[i].worst_factor = worst[i];
  }
  const std::vector<Table> tables = MakeTables(rows, o.SettingsJson());
  const auto it = std::find_if(tables.begin(), tables.end(), [](const Table& t) { return t.id == "diagnostics"; });
  ASSERT_NE(it, tables.end());
  ASSERT_EQ(it->rows.size(), 4u);
  EXPECT_EQ(it->rows[0][1], "bad");
  EXPECT_EQ(it->rows[1][1], "good");
  for (int k : {2, 3}) {
    EXPECT_EQ(it->rows[k][2], "n/a");
    EXPECT_EQ(it->rows[k][4].rfind("not scored: too few samples", 0), 0u) << it->rows[k][4];
  }
  bool median_said = false;
  for (const std::string& n : it->notes) {
    median_said |= n.rfind("g: median score 3 over 2 trajectories (2 of 4 too short to score, left out)", 0) == 0;
  }
  EXPECT_TRUE(median_said) << TableMarkdown(*it);
  rows.erase(rows.begin() + 1, rows.begin() + 3);  // none scored
  const std::vector<Table> none = MakeTables(rows, o.SettingsJson());
  const auto d = std::find_if(none.begin(), none.end(), [](const Table& t) { return t.id == "diagnostics"; });
  ASSERT_NE(d, none.end());
  EXPECT_NE(TableMarkdown(*d).find("g: no trajectory scored (2 of 2 too short to score, left out)"), std::string::npos)
      << TableMarkdown(*d);
}

TEST_F(Evaluation, RealMitRecordingWithFrozenForceHasNoForceRows) {
  const std::string rect = kMit + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.800_t=0.349.h5";
  if (!fs::exists(rect) || !fs::exists(kMit + "obj/rect1.obj")) GTEST_SKIP() << "no MIT data at " << kMit;
  EvaluationOptions o;
  o.protocols = ParseProtocols("table1");
  o.mit_rate = 50.0;
  const std::vector<EvaluationItem> items = PlanEvaluation({rect}, o);
  ASSERT_EQ(items.size(), 1u);
  EXPECT_EQ(items[0].group, "rect1");
  const EvaluationRow row = EvaluateItem(items[0], o);  // meshes found in ../../obj
  ASSERT_TRUE(row.error.empty()) << row.error;
  const std::vector<Table> tables = MakeTables({row}, o.SettingsJson());
  const Table& t1 = tables.at(0);
  EXPECT_LT(Cell(t1, "object position (moving)", "RMS"), Cell(t1, "object position (moving)", "raw RMS"));
  for (const auto& r : t1.rows) EXPECT_NE(r[2], "force");  // the frozen force stream is dropped
  // Unknown objects need a description.
  fs::create_directories(dir_ / "abs" / "blob1");
  fs::copy_file(rect, dir_ / "abs" / "blob1" / "motion_surface=abs_shape=blob1_x.h5");
  const EvaluationRow bad = EvaluateItem(PlanEvaluation({(dir_ / "abs" / "blob1" / "motion_surface=abs_shape=blob1_x.h5").string()}, o)[0], o);
  EXPECT_NE(bad.error.find("blob1"), std::string::npos) << bad.error;
}

// A z-up model exported with y up: every vertex (x, y, z) written as (x, z, -y).
void WriteYUpExport(const std::string& from, const std::string& to) {
  std::ifstream in(from);
  std::ofstream out(to);
  out.precision(17);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("v ", 0) == 0) {
      double x, y, z;
      std::istringstream(line.substr(2)) >> x >> y >> z;
      out << "v " << x << " " << z << " " << -y << "\n";
    } else {
      out << line << "\n";
    }
  }
}

// A folder of the dataset's meshes exported with y up (Blender's OBJ convention): rect1.obj read
// along z is its 90 x 12.7 mm side view, and the probe tip.obj, a cylinder standing along z now,
// read along y gave a disk the size of its side view. The group's recordings choose rect1's
// cross-section, the probe's round section is found, and the rows equal the shipped meshes'.
TEST_F(Evaluation, AFolderOfMeshesExportedWithYUpIsReadByTheirCrossSections) {
  const std::string rect_dir = kMit + "abs/rect1/";
  if (!fs::exists(rect_dir) || !fs::exists(kMit + "obj/rect1.obj")) GTEST_SKIP() << "no MIT data at " << kMit;
  const fs::path y_up = dir_ / "y_up";
  fs::create_directories(y_up);
  for (const std::string mesh : {"rect1.obj", "tip.obj"}) WriteYUpExport(kMit + "obj/" + mesh, (y_up / mesh).string());
  const ObjectModel model = MitObjectModel("rect1", y_up.string());
  const geometry::Box2 side = model.object.shape.bounds();
  EXPECT_NEAR(side.max.y() - side.min.y(), 0.0127, 1e-4) << "read along z, the side view";
  ASSERT_EQ(model.other_readings.size(), 1u);
  EXPECT_EQ(model.reading_axes[0], "y");
  EXPECT_NEAR(model.finger.shape.radius(), 0.0047, 1e-6) << "the probe's round section";
  EvaluationOptions o;
  o.protocols = ParseProtocols("table1");
  o.mit_rate = 50.0;
  const std::vector<std::string> files{rect_dir + "motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.700_t=-1.047.h5",
                                       rect_dir + "motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.800_t=0.349.h5"};
  EvaluationOptions exported = o, shipped = o;
  exported.mesh_dir = y_up.string();
  shipped.mesh_dir = kMit + "obj";
  std::vector<EvaluationItem> items = PlanEvaluation(files, exported), reference = PlanEvaluation(files, shipped);
  const std::vector<std::string> lines = RegisterGroups(items, exported);
  ASSERT_FALSE(lines.empty());
  EXPECT_NE(lines[0].find("contacts fit its cross-section along y, not its footprint along z"), std::string::npos) << lines[0];
  RegisterGroups(reference, shipped);
  for (std::size_t i = 0; i < items.size(); ++i) {
    ASSERT_TRUE(items[i].object_shape.has_value());
    EXPECT_FALSE(reference[i].object_shape.has_value());
    const EvaluationRow a = EvaluateItem(items[i], exported), b = EvaluateItem(reference[i], shipped);
    ASSERT_TRUE(a.error.empty() && b.error.empty()) << a.error << b.error;
    ASSERT_EQ(a.stats.size(), b.stats.size());
    for (const auto& [key, value] : b.stats) {
      ASSERT_TRUE(a.stats.count(key)) << key;
      if (key.find("/time/") != std::string::npos) continue;  // the solve's wall time
      EXPECT_NEAR(a.stats.at(key), value, 1e-9 * (1.0 + std::abs(value))) << key;
    }
  }
  // align_shape off: read along z as given, and said.
  exported.estimator.align_shape = graph::EstimatorConfig::AlignShape::kOff;
  std::vector<EvaluationItem> as_given = PlanEvaluation(files, exported);
  const std::vector<std::string> off = RegisterGroups(as_given, exported);
  ASSERT_EQ(off.size(), 1u);
  EXPECT_NE(off[0].find("its footprint is its side view (align_shape off"), std::string::npos) << off[0];
  EXPECT_FALSE(as_given[0].object_shape.has_value());
}

TEST_F(Evaluation, CommandReportsBadOptionsInOneLine) {
  const std::string out = (dir_ / "out").string();
  testing::ToolRun r = Exec("evaluate --simulate 1 --protocol table3 --out " + out);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("unknown protocol 'table3'"), std::string::npos) << r.err;
  r = Exec("evaluate --simulate 1 --shard 4/4 --out " + out);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("bad shard '4/4'"), std::string::npos) << r.err;
  r = Exec("evaluate " + (dir_ / "nope.h5").string() + " --out " + out);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("nope.h5"), std::string::npos) << r.err;
  r = Exec("evaluate --out " + out);
  EXPECT_NE(r.err.find("nothing to evaluate"), std::string::npos) << r.err;
  r = Exec("evaluate merge " + (dir_ / "none").string() + " --out " + out);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("none"), std::string::npos) << r.err;
  // A file that is not a push: counted, reported with its name; all failed -> status 1.
  r = Exec("evaluate " + Write("x.json", "[]") + " --protocol table1 -q --out " + out);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("x.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("every trajectory failed"), std::string::npos) << r.err;
  // Some failed: the tables are written without them, status 1 unless --allow-failures.
  const std::string good = (dir_ / "good.json").string();
  ASSERT_EQ(Exec("simulate -o " + good + " --duration 1").status, 0);
  const std::string partial = "evaluate " + good + " " + (dir_ / "x.json").string() + " --protocol table1 -q --out " + out;
  r = Exec(partial);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("1 of 2 trajectories failed; the tables leave them out"), std::string::npos) << r.err;
  EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(out) / "results.md"));
  r = Exec(partial + " --allow-failures");
  EXPECT_EQ(r.status, 0) << r.err;
}

}  // namespace
}  // namespace pushgraph::evaluation
