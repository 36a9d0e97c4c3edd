// server/status: every absl code maps to its gRPC code and back.
#include "server/status.h"

#include <grpcpp/grpcpp.h>

#include <utility>
#include <vector>

#include "client/client.h"
#include "gtest/gtest.h"

namespace stylus {
namespace {

TEST(StatusMappingTest, EveryCodeKeepsItsMeaningAndMessage) {
  const std::vector<std::pair<absl::Status, grpc::StatusCode>> cases = {
      {absl::OkStatus(), grpc::StatusCode::OK},
      {absl::InvalidArgumentError("a"), grpc::StatusCode::INVALID_ARGUMENT},
      {absl::NotFoundError("b"), grpc::StatusCode::NOT_FOUND},
      {absl::ResourceExhaustedError("c"), grpc::StatusCode::RESOURCE_EXHAUSTED},
      {absl::FailedPreconditionError("d"), grpc::StatusCode::FAILED_PRECONDITION},
      {absl::UnavailableError("e"), grpc::StatusCode::UNAVAILABLE},
      {absl::CancelledError("f"), grpc::StatusCode::CANCELLED},
      {absl::DeadlineExceededError("g"), grpc::StatusCode::DEADLINE_EXCEEDED},
      {absl::InternalError("h"), grpc::StatusCode::INTERNAL},
      {absl::AlreadyExistsError("i"), grpc::StatusCode::ALREADY_EXISTS},
      {absl::UnimplementedError("j"), grpc::StatusCode::UNIMPLEMENTED},
      {absl::DataLossError("k"), grpc::StatusCode::DATA_LOSS},
      {absl::OutOfRangeError("l"), grpc::StatusCode::OUT_OF_RANGE},
      {absl::PermissionDeniedError("m"), grpc::StatusCode::PERMISSION_DENIED},
      {absl::UnauthenticatedError("n"), grpc::StatusCode::UNAUTHENTICATED},
      {absl::AbortedError("o"), grpc::StatusCode::ABORTED},
      {absl::UnknownError("p"), grpc::StatusCode::UNKNOWN},
  };
  for (const auto& [in, code] : cases) {
    const grpc::Status out = server::ToGrpcStatus(in);
    EXPECT_EQ(out.error_code(), code) << in;
    EXPECT_EQ(out.error_message(), std::string(in.message()));
    EXPECT_EQ(FromGrpcStatus(out), in);  // And back, in the client.
  }
}

}  // namespace
}  // namespace stylus
