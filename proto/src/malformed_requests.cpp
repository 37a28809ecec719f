#include "bsls/rpc/malformed_requests.h"

#include <google/protobuf/descriptor.h>
#include <grpcpp/server_builder.h>
#include <grpcpp/support/server_interceptor.h>

#include <memory>
#include <string>
#include <vector>

namespace bsls::rpc {
namespace {

using grpc::experimental::InterceptionHookPoints;
using grpc::experimental::ServerRpcInfo;

// The request type of gRPC method "/package.Service/Method" ("" when the
// descriptor pool does not know it).
std::string RequestTypeOf(const char* method) {
  std::string name = method != nullptr ? method : "";
  if (!name.empty() && name[0] == '/') name.erase(0, 1);
  const std::size_t slash = name.find('/');
  if (slash == std::string::npos) return "";
  name[slash] = '.';
  const google::protobuf::MethodDescriptor* descriptor =
      google::protobuf::DescriptorPool::generated_pool()->FindMethodByName(name);
  return descriptor != nullptr ? descriptor->input_type()->full_name() : "";
}

// One call: notes a request that did not parse and rewrites its status.
class MalformedRequestInterceptor final : public grpc::experimental::Interceptor {
 public:
  explicit MalformedRequestInterceptor(ServerRpcInfo* info) : info_(info) {}

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    if (methods->QueryInterceptionHookPoint(InterceptionHookPoints::POST_RECV_MESSAGE) &&
        methods->GetRecvMessage() == nullptr)
      malformed_ = true;
    // gRPC answers a request that did not parse with INTERNAL (sync
    // handlers) or with UNIMPLEMENTED and no message (callback handlers).
    if (malformed_ &&
        methods->QueryInterceptionHookPoint(InterceptionHookPoints::PRE_SEND_STATUS) &&
        (methods->GetSendStatus().error_code() == grpc::StatusCode::INTERNAL ||
         (methods->GetSendStatus().error_code() == grpc::StatusCode::UNIMPLEMENTED &&
          methods->GetSendStatus().error_message().empty()))) {
      const std::string type = RequestTypeOf(info_->method());
      methods->ModifySendStatus(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                                             "request: the bytes received are not a " +
                                                 (type.empty() ? "request" : type) + " message"));
    }
    methods->Proceed();
  }

 private:
  ServerRpcInfo* info_;
  bool malformed_ = false;
};

class MalformedRequestInterceptorFactory final
    : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  grpc::experimental::Interceptor* CreateServerInterceptor(ServerRpcInfo* info) override {
    // A request stream's reads end the same way at a malformed message and
    // at the client's half-close: those calls keep their handler's status.
    if (info->type() != ServerRpcInfo::Type::UNARY &&
        info->type() != ServerRpcInfo::Type::SERVER_STREAMING)
      return nullptr;
    return new MalformedRequestInterceptor(info);
  }
};

}  // namespace

void ReportMalformedRequests(grpc::ServerBuilder& builder) {
  std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>> creators;
  creators.push_back(std::make_unique<MalformedRequestInterceptorFactory>());
  builder.experimental().SetInterceptorCreators(std::move(creators));
}

}  // namespace bsls::rpc
