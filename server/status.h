// The one place where absl::Status becomes grpc::Status (house rule 2).
#ifndef STYLUS_SERVER_STATUS_H_
#define STYLUS_SERVER_STATUS_H_

#include <grpcpp/support/status.h>

#include "absl/status/status.h"

namespace stylus::server {

// Same code (the numeric values of absl and gRPC codes agree; each is mapped
// explicitly all the same) and the same message.
grpc::Status ToGrpcStatus(const absl::Status& status);

}  // namespace stylus::server

#endif  // STYLUS_SERVER_STATUS_H_
