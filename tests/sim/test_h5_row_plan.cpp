// h5::File's row plans (common/h5_file.h): a slab row's chunks deflated
// ahead (prepare_row, here on two threads with a Deflater each) and handed to
// HDF5 as stored bytes (write_row), chunks of zeros only not at all. Oracle: what
// HDF5 reads back through its own deflate filter must be the values written,
// for the result file's chunkings (whole rows; rows split with an edge chunk
// past the dataset's end) and for one it cannot write directly (fallback).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <thread>
#include <vector>

#include "common/error.h"
#include "common/h5_file.h"
#include "tests/unique_temp_dir.h"

namespace fiberlab::h5 {
namespace {

std::vector<double> random_doubles(std::size_t n, std::uint32_t seed) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = i % 3 == 0 ? 0.0 : u(g);  // some runs of zeros
  return v;
}

std::vector<std::uint64_t> random_words(std::size_t n, std::uint32_t seed) {
  std::mt19937_64 g(seed);
  std::vector<std::uint64_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = i % 2 == 0 ? g() % 7 : g();  // (high, low) pairs
  return v;
}

TEST(H5RowPlan, ChunksDeflatedOnThreadsReadBackThroughHdf5) {
  const auto dir = test_support::unique_temp_dir("fiberlab_test_slab_rows");
  const std::string path = (dir / "rows.h5").string();
  // As in a result file: K x L x 90 x 180 x 3 float64 (a chunk is a whole
  // row), the same x 2 uint64 (chunks of 60 of the 90 rows: the second
  // reaches past the end), and a shape whose chunks split the last dimension.
  const Dims doubles_dims{2, 3, 90, 180, 3}, words_dims{2, 3, 90, 180, 3, 2}, odd_dims{2, 2, 2, 100000};
  const std::size_t row_doubles = 90 * 180 * 3, row_words = 2 * row_doubles, row_odd = 200000;
  std::vector<std::vector<double>> doubles, odd;
  std::vector<std::vector<std::uint64_t>> words;
  {
    File f = File::create(path);
    f.create_dataset("/d", doubles_dims, File::Type::Float64);
    f.create_dataset("/w", words_dims, File::Type::UInt64);
    f.create_dataset("/o", odd_dims, File::Type::Float64);
    File::RowPlan plans[3] = {f.plan_rows("/d"), f.plan_rows("/w"), f.plan_rows("/o")};
    EXPECT_TRUE(plans[0].direct);
    EXPECT_TRUE(plans[1].direct);
    EXPECT_FALSE(plans[2].direct);  // chunks split the last dimension: HDF5 filters it
    for (hsize_t i = 0; i < 2; ++i) {
      for (hsize_t j = 0; j < 3; ++j) {
        doubles.push_back(random_doubles(row_doubles, static_cast<std::uint32_t>(10 * i + j)));
        words.push_back(random_words(row_words, static_cast<std::uint32_t>(20 + 10 * i + j)));
      }
      for (hsize_t j = 0; j < 2; ++j) odd.push_back(random_doubles(row_odd, static_cast<std::uint32_t>(40 + 10 * i + j)));
      if (i == 1) {  // chunks of zeros only, which are not stored: a whole row, and a row's edge chunk
        std::fill(doubles[5].begin(), doubles[5].end(), 0.0);
        std::fill(words[5].begin() + 60 * 180 * 3 * 2, words[5].end(), 0);
      }
      // Rows 0..7 of this slab: /d j, /w j (j < 3), /o j (j < 2), prepared
      // on two threads (even and odd rows), each with its own Deflater.
      std::vector<File::PreparedRow> prepared(8);
      auto prepare = [&](int parity) {
        Deflater z(plans[0].level);
        for (int r = parity; r < 8; r += 2) {
          if (r < 6 && r % 2 == 0) File::prepare_row(plans[0], doubles[3 * i + r / 2], z, prepared[r]);
          else if (r < 6) File::prepare_row(plans[1], words[3 * i + r / 2], z, prepared[r]);
          else File::prepare_row(plans[2], odd[2 * i + (r - 6)], z, prepared[r]);
        }
      };
      std::thread even(prepare, 0), odd_rows(prepare, 1);
      even.join();
      odd_rows.join();
      if (i == 1) {
        EXPECT_TRUE(prepared[4].chunks[0].empty());
        EXPECT_FALSE(prepared[5].chunks[0].empty());
        EXPECT_TRUE(prepared[5].chunks[1].empty());
      }
      for (hsize_t j = 0; j < 3; ++j) {
        f.write_row(plans[0], i, j, prepared[2 * j]);
        f.write_row(plans[1], i, j, prepared[2 * j + 1]);
      }
      for (hsize_t j = 0; j < 2; ++j) f.write_row(plans[2], i, j, prepared[6 + j]);
    }
    for (const File::RowPlan& plan : plans) f.end_rows(plan);
    f.close();
  }
  const File f = File::open_read(path);
  for (hsize_t i = 0; i < 2; ++i) {
    const std::vector<double> d = f.read_slab_doubles("/d", i);
    const std::vector<std::uint64_t> w = f.read_slab_uint64s("/w", i);
    const std::vector<double> o = f.read_slab_doubles("/o", i);
    for (hsize_t j = 0; j < 3; ++j) {
      EXPECT_TRUE(std::equal(doubles[3 * i + j].begin(), doubles[3 * i + j].end(), d.begin() + j * row_doubles))
          << "/d slab " << i << " row " << j;
      EXPECT_TRUE(std::equal(words[3 * i + j].begin(), words[3 * i + j].end(), w.begin() + j * row_words))
          << "/w slab " << i << " row " << j;
    }
    for (hsize_t j = 0; j < 2; ++j)
      EXPECT_TRUE(std::equal(odd[2 * i + j].begin(), odd[2 * i + j].end(), o.begin() + j * row_odd))
          << "/o slab " << i << " row " << j;
  }
}

// Chunking of slab datasets (h5::File::create_dataset): a row along the
// second dimension (a lobe) is its own chunk when it holds 4096 cells or more
// (the counts of 90 x 180 bins: rows prepared on threads), and shares a chunk
// with the next rows when smaller (30 x 60 bins: written through HDF5).
TEST(H5RowPlan, ARowOf4096CellsOrMoreIsItsOwnChunk) {
  const auto dir = test_support::unique_temp_dir("fiberlab_test_row_chunks");
  File f = File::create((dir / "chunks.h5").string());
  f.create_dataset("/count", {1, 8, 90, 180}, File::Type::UInt64);
  f.create_dataset("/small", {1, 8, 30, 60}, File::Type::UInt64);
  f.create_dataset("/edge", {1, 8, 64, 64}, File::Type::UInt64);  // exactly 4096 cells a row
  EXPECT_TRUE(f.plan_rows("/count").direct);
  EXPECT_FALSE(f.plan_rows("/small").direct);
  EXPECT_TRUE(f.plan_rows("/edge").direct);
  f.close();
}

// A row of the wrong length or type, or a Deflater at another level, is an
// internal error named for the dataset, never a corrupt chunk.
TEST(H5RowPlan, RefusesRowsThatDoNotFitThePlan) {
  const auto dir = test_support::unique_temp_dir("fiberlab_test_row_plan");
  File f = File::create((dir / "plan.h5").string());
  f.create_dataset("/d", {1, 2, 90, 180, 3}, File::Type::Float64);
  const File::RowPlan plan = f.plan_rows("/d");
  ASSERT_TRUE(plan.direct);
  File::PreparedRow row;
  Deflater same(plan.level), other(plan.level == 6 ? 5 : 6);
  EXPECT_THROW(File::prepare_row(plan, std::vector<double>(90 * 180 * 3 - 1), same, row), Error);
  EXPECT_THROW(File::prepare_row(plan, std::vector<std::uint64_t>(90 * 180 * 3), same, row), Error);
  EXPECT_THROW(File::prepare_row(plan, std::vector<double>(90 * 180 * 3), other, row), Error);
  EXPECT_NO_THROW(File::prepare_row(plan, std::vector<double>(90 * 180 * 3), same, row));
  f.close();
}

// A plan made before the file exists (plan_new_rows) is the plan of the
// dataset create_dataset then makes, for direct and fallback layouts alike;
// attach opens the dataset into it, and refuses a dataset laid out otherwise.
TEST(H5RowPlan, PlanBeforeTheFileIsThePlanOfTheCreatedDataset) {
  const auto dir = test_support::unique_temp_dir("fiberlab_test_new_row_plan");
  File f = File::create((dir / "new.h5").string());
  const std::vector<std::pair<Dims, File::Type>> cases{
      {{1, 8, 90, 180, 3}, File::Type::Float64}, {{2, 8, 90, 180, 3}, File::Type::Int64},
      {{1, 8, 90, 180}, File::Type::UInt64},     {{1, 8, 30, 60}, File::Type::UInt64},
      {{1, 8, 64, 64}, File::Type::UInt64},      {{2, 2, 2, 100000}, File::Type::Float64}};
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const std::string name = "/d" + std::to_string(c);
    File::RowPlan planned = File::plan_new_rows(name, cases[c].first, cases[c].second);
    f.create_dataset(name, cases[c].first, cases[c].second);
    const File::RowPlan opened = f.plan_rows(name);
    EXPECT_EQ(planned.type, opened.type) << name;
    EXPECT_EQ(planned.direct, opened.direct) << name;
    EXPECT_EQ(planned.rows, opened.rows) << name;
    EXPECT_EQ(planned.rows_per_chunk, opened.rows_per_chunk) << name;
    EXPECT_EQ(planned.row_bytes, opened.row_bytes) << name;
    EXPECT_EQ(planned.level, opened.level) << name;
    EXPECT_NO_THROW(f.attach(planned)) << name;
    EXPECT_GE(planned.set.id(), 0) << name;
  }
  // A dataset of another shape than planned (its rows split differently).
  File::RowPlan wrong = File::plan_new_rows("/other", {1, 8, 90, 180, 3}, File::Type::Float64);
  f.create_dataset("/other", {1, 8, 120, 180, 3}, File::Type::Float64);
  EXPECT_THROW(f.attach(wrong), Error);
  f.close();
}

}  // namespace
}  // namespace fiberlab::h5
