// Output files (engine/io): what is written reads back equal; files appear whole or not at all.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include "asperity/io.hpp"
#include "asperity/world.hpp"

namespace fs = std::filesystem;
using namespace asperity;

namespace {

fs::path fresh_dir(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("asperity_io_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

bool has_temporaries(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp-") != std::string::npos) return true;
  return false;
}

}  // namespace

TEST(Json, WritesValuesReadably) {
  io::Json v = io::Json::Object{{"name", "run \"1\""},
                                {"n", 3},
                                {"x", 0.1},
                                {"bad", std::nan("")},
                                {"list", io::Json::Array{1, 2.5, true, nullptr}},
                                {"empty", io::Json::Object{}}};
  std::string text = io::to_json_text(v);
  EXPECT_NE(text.find("\"name\": \"run \\\"1\\\"\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"x\": 0.1"), std::string::npos) << "shortest round-trip form: " << text;
  EXPECT_NE(text.find("\"bad\": null"), std::string::npos);
  EXPECT_NE(text.find("[1, 2.5, true, null]"), std::string::npos);
  EXPECT_NE(text.find("\"empty\": {}"), std::string::npos);
}

TEST(AtomicFile, LeavesNothingWhenNotCommitted) {
  fs::path dir = fresh_dir("atomic");
  {
    io::AtomicFile f(dir / "out.txt");
    std::ofstream(f.temp_path()) << "partial";
    EXPECT_TRUE(fs::exists(f.temp_path()));
  }
  EXPECT_FALSE(fs::exists(dir / "out.txt"));
  EXPECT_FALSE(has_temporaries(dir));
  io::write_text_file(dir / "out.txt", "whole");
  EXPECT_EQ(read_text(dir / "out.txt"), "whole");
  EXPECT_FALSE(has_temporaries(dir));
  EXPECT_THROW(io::write_text_file(dir / "missing" / "x.txt", "x"), Error);
  fs::remove_all(dir);
}

TEST(Series, Hdf5AndCsvReadBackExactly) {
  fs::path dir = fresh_dir("series");
  io::Series s({{"time", "s"}, {"force", "N"}, {"ratio", ""}});
  for (int i = 0; i < 50; ++i) {
    double row[3] = {i * 0.1, std::sin(i * 0.37) * 1e-7, 1.0 / (i + 1)};
    s.append_row(row);
  }
  s.attributes().emplace_back("kn", 1e4);
  s.attributes().emplace_back("label", std::string("test"));
  s.write_hdf5(dir / "s.h5");
  s.write_csv(dir / "s.csv");

  EXPECT_EQ(io::hdf5_datasets(dir / "s.h5"), (std::vector<std::string>{"/force", "/ratio", "/time"}));
  for (const io::Column& c : s.columns()) {
    EXPECT_EQ(io::read_hdf5(dir / "s.h5", "/" + c.name), c.values) << c.name;
    auto units = io::read_hdf5_attribute(dir / "s.h5", "/" + c.name, "units");
    if (c.unit.empty()) {
      EXPECT_FALSE(units.has_value());
    } else {
      ASSERT_TRUE(units.has_value());
      EXPECT_EQ(std::get<std::string>(*units), c.unit);
    }
  }
  EXPECT_EQ(std::get<double>(*io::read_hdf5_attribute(dir / "s.h5", "/", "kn")), 1e4);
  EXPECT_EQ(std::get<std::string>(*io::read_hdf5_attribute(dir / "s.h5", "/", "label")), "test");
  EXPECT_EQ(std::get<std::string>(*io::read_hdf5_attribute(dir / "s.h5", "/", "columns")), "time,force,ratio");

  std::ifstream csv(dir / "s.csv");
  std::string header, line;
  std::getline(csv, header);
  EXPECT_EQ(header, "time [s],force [N],ratio");
  for (std::size_t i = 0; std::getline(csv, line); ++i) {
    std::stringstream cells(line);
    std::string cell;
    for (std::size_t j = 0; std::getline(cells, cell, ','); ++j)
      EXPECT_EQ(std::stod(cell), s.column(j).values[i]) << "row " << i << " column " << j;
  }
  EXPECT_FALSE(has_temporaries(dir));
  fs::remove_all(dir);
}

TEST(Series, RejectsBadColumns) {
  using Names = std::vector<std::pair<std::string, std::string>>;
  EXPECT_THROW(io::Series(Names{{"a/b", ""}}), Error);
  EXPECT_THROW(io::Series(Names{{"a", ""}, {"a", ""}}), Error);
  io::Series s(Names{{"a", ""}, {"b", ""}});
  double one[1] = {1};
  EXPECT_THROW(s.append_row(one), Error);
}

TEST(Snapshot, ParticlesAndContactsReadBack) {
  fs::path dir = fresh_dir("snapshot");
  WorldSettings settings;
  settings.contact.kn = 1e3;
  settings.gravity = {0, 0, -9.81};
  World world(settings);
  world.add_plane({0, 0, 0}, {0, 0, 1}, settings.contact);
  // a column standing on the floor: gravity keeps its contacts closed
  for (int i = 0; i < 10; ++i) world.add_particle({0, 0, 0.0099 + 0.0199 * i}, 0.01);
  std::int64_t ids[2] = {0, 1};
  world.add_group(ids);
  world.cycle(20);

  io::SnapshotSeries series(dir, "p");
  io::Snapshot snap = io::take_snapshot(world, true, 1);
  ASSERT_GT(snap.id_a.size(), 0u) << "the test needs contacts";
  fs::path file = series.write(snap);
  series.write(io::take_snapshot(world, true, 1));

  EXPECT_EQ(io::read_hdf5(file, "/particles/position"), world.positions());
  EXPECT_EQ(io::read_hdf5(file, "/particles/velocity"), world.velocities());
  EXPECT_EQ(io::read_hdf5(file, "/particles/radius"), world.radii());
  EXPECT_EQ(io::hdf5_shape(file, "/particles/position"), (std::vector<std::size_t>{10, 3}));
  std::vector<double> id = io::read_hdf5(file, "/particles/id");
  std::vector<double> group = io::read_hdf5(file, "/particles/group");
  for (std::size_t i = 0; i < 10; ++i) {
    EXPECT_EQ(id[i], double(i + 1));
    EXPECT_EQ(group[i], i < 2 ? 1.0 : -1.0);
  }
  std::vector<ContactInfo> contacts = world.contacts();
  std::vector<double> fn = io::read_hdf5(file, "/contacts/normal_force");
  std::vector<double> pair = io::read_hdf5(file, "/contacts/pair");
  ASSERT_EQ(fn.size(), contacts.size());
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    EXPECT_EQ(fn[k], contacts[k].normal_force);
    EXPECT_EQ(pair[2 * k], double(contacts[k].id_a));  // rows of the particle arrays
    EXPECT_EQ(pair[2 * k + 1], double(contacts[k].id_b));
  }
  EXPECT_EQ(std::get<std::int64_t>(*io::read_hdf5_attribute(file, "/", "step")), 20);
  EXPECT_EQ(std::get<std::string>(*io::read_hdf5_attribute(file, "/particles/velocity", "units")), "m/s");

  std::string xdmf = read_text(series.xdmf_path());
  EXPECT_NE(xdmf.find("p_000000.h5:/particles/position"), std::string::npos);
  EXPECT_NE(xdmf.find("p_000001.h5:/particles/position"), std::string::npos);
  EXPECT_NE(xdmf.find("TopologyType=\"Polyvertex\" NumberOfElements=\"10\""), std::string::npos);
  std::string contacts_xdmf = read_text(series.contacts_xdmf_path());
  EXPECT_NE(contacts_xdmf.find("TopologyType=\"Polyline\""), std::string::npos);
  EXPECT_FALSE(has_temporaries(dir));
  fs::remove_all(dir);
}

// A series indexed by another quantity (the shear displacement): XDMF times and labels from the
// script, displacements since the first snapshot, particles of one tag left out with the contacts'
// rows renumbered, and a new series removing an earlier one's files.
TEST(Snapshot, IndexTimeDisplacementExclusionAndStaleFiles) {
  fs::path dir = fresh_dir("snapshot_index");
  {
    std::ofstream(dir / "p_000007.h5") << "stale";
    std::ofstream(dir / "p.xdmf") << "stale";
    std::ofstream(dir / "p_contacts.xdmf") << "stale";
    std::ofstream(dir / "p_notes.txt") << "kept";
    std::ofstream(dir / "p_closure_000000.h5") << "another series";
  }
  WorldSettings settings;
  settings.contact.kn = 1e3;
  World world(settings);
  // three touching spheres in a row; the middle one tagged 3 (left out of the files)
  for (int i = 0; i < 3; ++i) world.add_particle({0.0199 * i, 0, 0}, 0.01);
  std::int64_t middle[1] = {1};
  world.set_tag(middle, 3);
  std::int64_t last[1] = {2};
  world.set_tag(last, 2);
  world.cycle(1);
  ASSERT_EQ(world.contacts().size(), 2u) << "the test needs both contacts";

  io::SnapshotSeriesOptions options;
  options.time_label = "shear displacement (mm)";
  options.keys = {{"tag_key", std::string("2: upper half")}};
  io::SnapshotSeries series(dir, "p", options);
  EXPECT_FALSE(fs::exists(dir / "p_000007.h5"));
  EXPECT_FALSE(fs::exists(dir / "p_contacts.xdmf"));
  EXPECT_TRUE(fs::exists(dir / "p_notes.txt"));
  EXPECT_TRUE(fs::exists(dir / "p_closure_000000.h5"));

  auto take = [&](double index_time, bool drop_middle) {
    io::Snapshot s = io::take_snapshot(world, true, 1);
    s.index_time = index_time;
    if (drop_middle) io::drop_particles(s, {true, false, true});
    return series.write(std::move(s));
  };
  std::vector<double> x0 = io::read_hdf5(take(0.0, false), "/particles/position");
  world.set_position(2, {0.05, 0.01, -0.02});
  fs::path file = take(2.5, true);

  std::vector<double> id = io::read_hdf5(file, "/particles/id");
  EXPECT_EQ(id, (std::vector<double>{1, 3}));
  std::vector<double> u = io::read_hdf5(file, "/particles/displacement");
  ASSERT_EQ(u.size(), 6u);
  EXPECT_DOUBLE_EQ(u[3], 0.05 - x0[6]);
  EXPECT_DOUBLE_EQ(u[4], 0.01 - x0[7]);
  EXPECT_DOUBLE_EQ(u[5], -0.02 - x0[8]);
  EXPECT_EQ(u[0], 0.0);
  EXPECT_EQ(io::read_hdf5(file, "/particles/tag"), (std::vector<double>{0, 2}));
  EXPECT_EQ(io::hdf5_shape(file, "/particles/force"), (std::vector<std::size_t>{2, 3}));
  EXPECT_EQ(io::hdf5_shape(file, "/particles/angular_velocity"), (std::vector<std::size_t>{2, 3}));
  // both contacts touched the left-out middle sphere: none is left
  EXPECT_EQ(io::read_hdf5(file, "/contacts/normal_force").size(), 0u);
  EXPECT_EQ(std::get<std::string>(*io::read_hdf5_attribute(file, "/particles", "tag_key")), "2: upper half");
  EXPECT_DOUBLE_EQ(std::get<double>(*io::read_hdf5_attribute(file, "/", "index_time")), 2.5);

  std::string xdmf = read_text(series.xdmf_path());
  EXPECT_NE(xdmf.find("<Time Value=\"2.5\"/>"), std::string::npos);
  EXPECT_NE(xdmf.find("<Information Name=\"time\" Value=\"shear displacement (mm)\"/>"), std::string::npos);
  EXPECT_NE(xdmf.find("<Information Name=\"tag_key\" Value=\"2: upper half\"/>"), std::string::npos);
  EXPECT_NE(xdmf.find("TopologyType=\"Polyvertex\" NumberOfElements=\"2\""), std::string::npos);
  EXPECT_NE(xdmf.find("Attribute Name=\"displacement\""), std::string::npos);
  fs::remove_all(dir);
}

// A resumed run continues its series (SnapshotSeriesOptions::keep): the kept snapshots stay, the
// later ones an interrupted run wrote go, the index and the displacements go on as if unbroken.
TEST(Snapshot, KeepContinuesASeriesAsIfUnbroken) {
  fs::path dir = fresh_dir("snapshot_keep");
  fs::path other = fresh_dir("snapshot_keep_unbroken");
  WorldSettings settings;
  settings.contact.kn = 1e3;
  World world(settings);
  for (int i = 0; i < 3; ++i) world.add_particle({0.0199 * i, 0, 0}, 0.01);
  world.cycle(1);
  auto take = [&](double index_time) {
    io::Snapshot s = io::take_snapshot(world, true, 1);
    s.index_time = index_time;
    return s;
  };
  io::SnapshotSeriesOptions options;
  options.time_label = "closure (mm)";
  io::SnapshotSeries unbroken(other, "p", options);
  {
    io::SnapshotSeries first(dir, "p", options);
    first.write(take(0.0));
    unbroken.write(take(0.0));
    world.set_position(2, {0.05, 0.01, -0.02});
    first.write(take(1.0));
    unbroken.write(take(1.0));
    first.write(take(2.0));  // written after the state the run resumes from: goes
  }
  options.keep = 2;
  io::SnapshotSeries resumed(dir, "p", options);
  EXPECT_EQ(resumed.count(), 2u);
  EXPECT_TRUE(fs::exists(dir / "p_000001.h5"));
  EXPECT_FALSE(fs::exists(dir / "p_000002.h5"));
  world.set_position(1, {0.02, 0.03, 0.0});
  const fs::path file = resumed.write(take(2.0));
  const fs::path same = unbroken.write(take(2.0));
  EXPECT_EQ(file.filename(), "p_000002.h5");
  EXPECT_EQ(io::read_hdf5(file, "/particles/displacement"), io::read_hdf5(same, "/particles/displacement"));
  EXPECT_NE(io::read_hdf5(file, "/particles/displacement"), std::vector<double>(9, 0.0));
  EXPECT_EQ(read_text(resumed.xdmf_path()), read_text(unbroken.xdmf_path()));
  EXPECT_EQ(read_text(resumed.contacts_xdmf_path()), read_text(unbroken.contacts_xdmf_path()));

  options.keep = 5;  // more than there are
  try {
    io::SnapshotSeries wrong(dir, "p", options);
    ADD_FAILURE() << "keep beyond the files on disk must be refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("p_000003.h5 (snapshot 4 of 5) is missing"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
  fs::remove_all(other);
}

TEST(Snapshot, DropParticlesRenumbersTheContactRows) {
  WorldSettings settings;
  settings.contact.kn = 1e3;
  World world(settings);
  for (int i = 0; i < 4; ++i) world.add_particle({0.0199 * i, 0, 0}, 0.01);
  world.cycle(1);
  io::Snapshot s = io::take_snapshot(world, true, 1);
  ASSERT_EQ(s.index_a.size(), 3u);
  io::drop_particles(s, {false, true, true, true});   // the first sphere goes, and its contact
  ASSERT_EQ(s.index_a.size(), 2u);
  EXPECT_EQ(s.id, (std::vector<std::int64_t>{2, 3, 4}));
  for (std::size_t k = 0; k < 2; ++k) {
    // rows point at the same particles as the ids
    EXPECT_EQ(s.id[static_cast<std::size_t>(s.index_a[k])], s.id_a[k]);
    EXPECT_EQ(s.id[static_cast<std::size_t>(s.index_b[k])], s.id_b[k]);
  }
  EXPECT_EQ(s.position.size(), 9u);
  EXPECT_EQ(s.force.size(), 9u);
}

TEST(Hdf5, ReadingErrorsNameTheProblem) {
  fs::path dir = fresh_dir("h5errors");
  try {
    io::read_hdf5(dir / "none.h5", "/x");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos);
  }
  io::Series s(std::vector<std::pair<std::string, std::string>>{{"a", "m"}});
  s.write_hdf5(dir / "s.h5");
  try {
    io::read_hdf5(dir / "s.h5", "/b");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no dataset /b"), std::string::npos);
  }
  fs::remove_all(dir);
}

TEST(Plot, DrawsAPngWithGnuplot) {
  if (!io::gnuplot_available()) GTEST_SKIP() << "gnuplot not installed";
  fs::path dir = fresh_dir("plot");
  io::Column x{"time", "s", {0, 1, 2, 3}};
  io::Column y{"energy", "J", {1, 0.5, 0.25, 0.125}};
  io::PlotOptions options;
  options.title = "it's a test";  // a quote must survive gnuplot's quoting
  io::plot_png(dir / "p.png", x, std::span<const io::Column>(&y, 1), options);
  std::string png = read_text(dir / "p.png");
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  EXPECT_FALSE(has_temporaries(dir));
  io::Column bad{"short", "", {1}};
  EXPECT_THROW(io::plot_png(dir / "q.png", x, std::span<const io::Column>(&bad, 1)), Error);
  fs::remove_all(dir);
}
