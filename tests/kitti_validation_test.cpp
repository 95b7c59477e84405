// Every field of every file format is checked (finite, size > 0, in range),
// directories are refused as such, and each error names file, line, field and what was expected.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "dlslot/config.hpp"
#include "dlslot/input_error.hpp"
#include "dlslot/kitti.hpp"
#include "text_file.hpp"

using namespace dlslot;
using namespace dlslot::kitti;
using dlslot::test::readText;
namespace fs = std::filesystem;

namespace {

fs::path dir() {
  const fs::path d = fs::temp_directory_path() / "dlslot_kitti_validation_test";
  fs::create_directories(d);
  return d;
}

std::string file(const std::string& name, const std::string& content) {
  const std::string path = (dir() / name).string();
  std::ofstream(path) << content;
  return path;
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

// FILE:LINE: FIELD: expected ...
void expectMessage(const std::string& what, const std::string& path, int line, const std::string& field,
                   const std::string& expected) {
  const std::string head = path + (line > 0 ? ":" + std::to_string(line) : "") + ": " + field;
  EXPECT_EQ(what.rfind(head, 0), 0u) << what << "\n  should start with: " << head;
  EXPECT_NE(what.find(expected), std::string::npos) << what << "\n  should say: " << expected;
}

const std::string kLabel = "0 1 Car 0 0 -1.5 100 100 200 200 1.5 1.6 3.9 2.0 1.6 10.0 -1.6\n";

}  // namespace

TEST(KittiValidation, LabelFieldsMustBeFiniteSizedAndInRange) {
  const std::string good = file("good.txt", kLabel + "0 -1 DontCare -1 -1 -10 1 1 5 5 -1 -1 -1 -1000 -1000 -1000 -10\n");
  EXPECT_EQ(readTrackingLabels(good).size(), 2u);  // DontCare keeps its -1 sizes

  std::string p = file("nan.txt", kLabel + "1 1 Car 0 0 -1.5 100 100 200 200 1.5 nan 3.9 2.0 1.6 10.0 -1.6\n");
  expectMessage(errorOf([&] { readTrackingLabels(p); }), p, 2, "w", "expected a finite number, got 'nan'");
  p = file("inf.txt", "0 1 Car 0 0 -1.5 100 100 200 200 1.5 1.6 3.9 inf 1.6 10.0 -1.6\n");
  expectMessage(errorOf([&] { readTrackingLabels(p); }), p, 1, "location", "expected a finite number");
  p = file("negative.txt", "0 1 Car 0 0 -1.5 100 100 200 200 -1.5 1.6 3.9 2.0 1.6 10.0 -1.6\n");
  expectMessage(errorOf([&] { readTrackingLabels(p); }), p, 1, "h", "expected a size > 0 m");
  p = file("zero.txt", "0 1 Car 0 0 -1.5 100 100 200 200 1.5 1.6 0 2.0 1.6 10.0 -1.6\n");
  expectMessage(errorOf([&] { readTrackingLabels(p); }), p, 1, "l", "expected a size > 0 m");
  p = file("id.txt", "0 99999999999 Car 0 0 -1.5 100 100 200 200 1.5 1.6 3.9 2.0 1.6 10.0 -1.6\n");
  expectMessage(errorOf([&] { readTrackingLabels(p); }), p, 1, "track id", "expected an integer in -1..999999");
  p = file("frame.txt", "1000000000 1 Car 0 0 -1.5 100 100 200 200 1.5 1.6 3.9 2.0 1.6 10.0 -1.6\n");
  expectMessage(errorOf([&] { readTrackingLabels(p); }), p, 1, "frame", "expected an integer in 0..999999");
  p = file("score.txt", "0 1 Car 0 0 -1.5 100 100 200 200 1.5 1.6 3.9 2.0 1.6 10.0 -1.6 -nan\n");
  expectMessage(errorOf([&] { readTrackingLabels(p); }), p, 1, "score", "expected a finite number");
}

TEST(KittiValidation, CsvDetectionFieldsMustBeFiniteAndSized) {
  const std::string row = "0,2,100,100,200,200,0.9,1.5,1.6,3.9,2.0,1.6,10.0,-1.6,-1.5\n";
  EXPECT_EQ(readCsvDetections(file("good.csv", row)).size(), 1u);
  std::string p = file("nan.csv", row + "1,2,100,100,200,200,NaN,1.5,1.6,3.9,2.0,1.6,10.0,-1.6,-1.5\n");
  expectMessage(errorOf([&] { readCsvDetections(p); }), p, 2, "score", "expected a finite number");
  p = file("neg.csv", "0,2,100,100,200,200,0.9,1.5,-1.6,3.9,2.0,1.6,10.0,-1.6,-1.5\n");
  expectMessage(errorOf([&] { readCsvDetections(p); }), p, 1, "w", "expected a size > 0 m");
  p = file("frame.csv", "-3,2,100,100,200,200,0.9,1.5,1.6,3.9,2.0,1.6,10.0,-1.6,-1.5\n");
  expectMessage(errorOf([&] { readCsvDetections(p); }), p, 1, "frame", "expected an integer in 0..999999");
}

TEST(KittiValidation, PosesTimesOxtsAndCalibMustBeFinite) {
  std::string p = file("poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 inf 0 1 0 0 0 0 1 0\n");
  expectMessage(errorOf([&] { readPoses(p); }), p, 2, "pose", "expected a finite number");
  p = file("scaled.txt", "2 0 0 0 0 1 0 0 0 0 1 0\n");
  expectMessage(errorOf([&] { readPoses(p); }), p, 1, "pose", "expected a rotation");
  p = file("times.txt", "0.0\nnan\n");
  expectMessage(errorOf([&] { readTimes(p); }), p, 2, "time", "expected a finite number");
  std::string oxts;
  for (int i = 0; i < 30; ++i) oxts += i == 3 ? "inf " : "1 ";
  p = file("oxts.txt", oxts + "\n");
  expectMessage(errorOf([&] { readOxts(p); }), p, 1, "field 4", "expected a finite number");
  p = file("calib.txt", "Tr_velo_cam 0 -1 0 0 0 0 -1 -0.08 1 0 0 nan\n");
  expectMessage(errorOf([&] { readCalib(p); }), p, 1, "Tr_velo_cam", "expected a finite number");
}

TEST(KittiValidation, DirectoriesAreRefusedAsSuch) {
  const std::string d = (dir() / "a_directory").string();
  fs::create_directories(d);
  for (const auto& read : std::vector<std::function<void()>>{
           [&] { readTrackingLabels(d); }, [&] { readCsvDetections(d); }, [&] { readVelodyne(d); },
           [&] { readPoses(d); }, [&] { readOxts(d); }, [&] { readCalib(d); }, [&] { readTimes(d); }}) {
    const std::string what = errorOf(read);
    EXPECT_EQ(what, d + ": is a directory, expected a file");
  }
  EXPECT_EQ(errorOf([&] { loadConfig(d); }), d + ": is a directory, expected a config file");
}

TEST(KittiValidation, EvalRefusesAMisspeltConfigSection) {
  std::string text = readText(std::string(DLSLOT_SOURCE_DIR) + "/config/dlslot.yaml");
  text.replace(text.find("\ntracker:"), 9, "\ntraker:");
  const std::string cfg = file("misspelt.yaml", text);
  const std::string err = (dir() / "eval.err").string();
  const std::string cmd = std::string(DLSLOT_BIN_DIR) + "/dlslot-eval --config " + cfg + " --traj " +
                          file("est.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n") + " 2> " + err;
  const int status = std::system(cmd.c_str());
  EXPECT_EQ(WEXITSTATUS(status), 2);
  const std::string es = readText(err);
  EXPECT_NE(es.find(cfg + ": traker"), std::string::npos) << es;
  EXPECT_NE(es.find("unknown key"), std::string::npos) << es;
}
