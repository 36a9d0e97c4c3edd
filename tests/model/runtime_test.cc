// The start-up report of the BLAS kernel LibTorch's products run on.
#include "model/runtime.h"

#include "gtest/gtest.h"

namespace stylus::model {
namespace {

TEST(BlasReportTest, AnOldKernelOnAModernCpuIsWarnedWithTheFix) {
  const std::string avx512 = "fpu sse2 avx avx2 fma avx512f avx512bw";
  BlasReport r = AdviseBlas("OpenBLAS 0.3.21", "Prescott", avx512);
  EXPECT_EQ(r.best, "Haswell");
  EXPECT_NE(r.warning.find("Prescott"), std::string::npos) << r.warning;
  EXPECT_NE(r.warning.find("OPENBLAS_CORETYPE=Haswell"), std::string::npos) << r.warning;
  r = AdviseBlas("OpenBLAS 0.3.21", "Sandybridge", "fpu sse2 avx avx2 fma");
  EXPECT_NE(r.warning.find("OPENBLAS_CORETYPE=Haswell"), std::string::npos) << r.warning;
}

TEST(BlasReportTest, AModernKernelOrAnOldCpuIsNotWarned) {
  EXPECT_EQ(AdviseBlas("OpenBLAS", "Haswell", "avx avx2 fma avx512f").warning, "");
  EXPECT_EQ(AdviseBlas("OpenBLAS", "SkylakeX", "avx avx2 fma avx512f").warning, "");
  EXPECT_EQ(AdviseBlas("OpenBLAS", "Prescott", "fpu sse2").warning, "");
  EXPECT_EQ(AdviseBlas("unknown", "", "avx2 fma").warning, "") << "a library that does not say";
}

TEST(BlasReportTest, ThisProcessNamesItsLibrary) {
  const BlasReport r = DescribeBlas();
  EXPECT_FALSE(r.library.empty());
  // Debian's LibTorch runs on OpenBLAS (scripts/setup installs the OpenMP build).
  EXPECT_NE(r.library.find("OpenBLAS"), std::string::npos) << r.library;
  EXPECT_FALSE(r.kernel.empty());
}

}  // namespace
}  // namespace stylus::model
