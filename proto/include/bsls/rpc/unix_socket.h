// The Unix sockets the services listen on (bslsd's own listener, the
// processing service's gRPC one): a second instance refuses to take over
// a socket that a live server still answers on, while a stale file left by
// a dead one is replaced.
//
// Thread-safety: pure function (and the file system).
#ifndef BSLS_RPC_UNIX_SOCKET_H_
#define BSLS_RPC_UNIX_SOCKET_H_

#include <string>

namespace bsls::rpc {

// Makes `path` free for a new listener: a stale socket file left by a dead
// server is removed. Returns why it cannot be ("<path> exists and is not a
// socket", "another live instance serves <path>"; nothing is removed then),
// or "" when the path is free.
std::string ClaimUnixSocketPath(const std::string& path);

}  // namespace bsls::rpc

#endif  // BSLS_RPC_UNIX_SOCKET_H_
