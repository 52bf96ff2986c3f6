// RayInput: records read in place; six-float rays converted block by block
// into exactly the records a scalar copy makes, for every block start and
// length on even and odd batch sizes (the vector path takes two rays at a
// time and reads past a pair only where a later ray exists: here the batch
// ends at an unmapped page, so a read past its end faults).
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstring>
#include <limits>
#include <span>
#include <stdexcept>
#include <vector>

#include "core/ray_input.h"

namespace hprt {
namespace {

// n six-float rays ending exactly where a PROT_NONE page begins.
class GuardedRays {
 public:
  explicit GuardedRays(size_t n) : n_(n) {
    const size_t page = size_t(sysconf(_SC_PAGESIZE));
    const size_t bytes = 6 * n * sizeof(float);
    data_pages_ = (bytes + page - 1) / page;
    size_ = (data_pages_ + 1) * page;
    base_ = static_cast<char*>(
        mmap(nullptr, size_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
    if (base_ == MAP_FAILED) throw std::runtime_error("mmap failed");
    if (mprotect(base_ + data_pages_ * page, page, PROT_NONE) != 0)
      throw std::runtime_error("mprotect failed");
    floats_ = reinterpret_cast<float*>(base_ + data_pages_ * page - bytes);
    for (size_t i = 0; i < 6 * n; ++i) floats_[i] = float(i) * 0.5f - 7.0f;
  }
  ~GuardedRays() { munmap(base_, size_); }
  GuardedRays(const GuardedRays&) = delete;
  GuardedRays& operator=(const GuardedRays&) = delete;

  std::span<const float> six() const { return {floats_, 6 * n_}; }

 private:
  size_t n_, data_pages_ = 0, size_ = 0;
  char* base_ = nullptr;
  float* floats_ = nullptr;
};

TEST(RayInput, SixFloatBlocksAreTheScalarRecordsAndStayInsideTheBatch) {
  const float tnear = 0.25f, tfar = std::numeric_limits<float>::infinity();
  for (const size_t n :
       {size_t(1), size_t(2), size_t(3), size_t(16), size_t(17), size_t(40), size_t(41)}) {
    const GuardedRays rays(n);
    const RayInput input(rays.six(), tnear, tfar);
    ASSERT_EQ(input.size(), n);
    EXPECT_EQ(input.records(), nullptr);
    for (size_t first = 0; first < n; ++first)
      for (size_t count = 0; first + count <= n; ++count) {
        std::vector<Ray> buf(count + 1);
        buf[count].tnear = 99.0f;  // past the block: untouched
        const Ray* got = input.block(first, count, buf.data());
        ASSERT_EQ(got, buf.data());
        for (size_t i = 0; i < count; ++i) {
          const float* q = rays.six().data() + 6 * (first + i);
          const Ray want{{q[0], q[1], q[2]}, tnear, {q[3], q[4], q[5]}, tfar};
          ASSERT_EQ(std::memcmp(&got[i], &want, sizeof(Ray)), 0)
              << "n " << n << " first " << first << " count " << count << " ray " << i;
        }
        ASSERT_EQ(buf[count].tnear, 99.0f);
      }
  }
}

TEST(RayInput, RecordsInPlaceAndSixFloatLengthChecked) {
  std::vector<Ray> records(5);
  const RayInput input(records);
  EXPECT_EQ(input.size(), 5u);
  EXPECT_EQ(input.records(), records.data());
  Ray unused[1];
  EXPECT_EQ(input.block(3, 2, unused), records.data() + 3);
  const std::vector<float> seven(7);
  EXPECT_THROW(RayInput(seven, 0.0f, 1.0f), std::invalid_argument);
  EXPECT_EQ(RayInput(std::span<const float>(), 0.0f, 1.0f).size(), 0u);
}

}  // namespace
}  // namespace hprt
