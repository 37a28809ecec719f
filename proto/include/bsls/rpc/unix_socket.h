// The Unix sockets the services listen on (bslsd's own listener, the
// processing service's gRPC one): whether a live server still answers on
// one, so that a second instance refuses to take it over while a stale
// file left by a dead one is replaced.
//
// Thread-safety: pure function (and the file system).
#ifndef BSLS_RPC_UNIX_SOCKET_H_
#define BSLS_RPC_UNIX_SOCKET_H_

#include <string>

namespace bsls::rpc {

// True when something accepts connections on the Unix socket at `path`
// (false for no file, a stale socket, or a path too long for a socket).
bool UnixSocketIsLive(const std::string& path);

}  // namespace bsls::rpc

#endif  // BSLS_RPC_UNIX_SOCKET_H_
