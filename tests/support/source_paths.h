// Where the checkout and the build are, for tests and benchmarks: their
// STYLUS_SOURCE_DIR and STYLUS_BINARY_DIR expand to these calls (CMake's
// stylus_source_paths), and only one small generated file holds the paths.
// So the objects of a test or benchmark do not depend on the folder the
// checkout is in, and a fresh clone elsewhere reuses them from ccache.
#ifndef STYLUS_TESTS_SUPPORT_SOURCE_PATHS_H_
#define STYLUS_TESTS_SUPPORT_SOURCE_PATHS_H_

namespace stylus::paths {

const char* SourceDir();  // The checkout's root.
const char* BinaryDir();  // The CMake build directory.

}  // namespace stylus::paths

#endif  // STYLUS_TESTS_SUPPORT_SOURCE_PATHS_H_
