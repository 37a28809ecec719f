// Who may do what on bslsd: a caller
// is identified by the transport (the peer's uid from SO_PEERCRED on the Unix
// socket, the client certificate's common name on mutual-TLS TCP) and mapped
// to one role. Roles are ordered: each may do everything of the one before.
//   viewer    status, preview, read captures, slide state, events
//   operator  + grab, select camera, gain, slides, focus, lamp
//   admin     + delete captures
//
// Thread-safety: RolePolicy is immutable after construction; RoleOf is safe
// from any thread.
#ifndef BSLS_SERVICE_ROLES_H_
#define BSLS_SERVICE_ROLES_H_

#include <sys/types.h>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace bsls::service {

enum class Role : int { kNone = 0, kViewer = 1, kOperator = 2, kAdmin = 3 };

// "none", "viewer", "operator", "admin".
std::string_view ToString(Role role);
// Parses the names of ToString; nullopt for anything else.
std::optional<Role> ParseRole(std::string_view text);

// The caller of one RPC, as the daemon logs it.
struct Caller {
  std::int64_t uid = -1;  // local callers; -1 for TCP
  std::string name;       // user name, or the certificate's common name
  std::string transport;  // "unix" or "tcp"
  Role role = Role::kNone;

  // "alice (uid 1000, unix, operator)" for logs and capture metadata.
  std::string Describe() const;
};

// Maps callers to roles. A local user's role is the highest of its own entry
// and the entries of every group it belongs to; `others` for everyone else.
struct RolePolicy {
  std::map<uid_t, Role> users;
  std::map<gid_t, Role> groups;
  Role others = Role::kNone;
  std::map<std::string, Role> certificate_names;  // TLS client certificate CN -> role

  // The role of local user `uid` (groups from the user database).
  Role RoleOfUid(uid_t uid) const;
  // The role of a TLS client whose certificate names `common_name`.
  Role RoleOfCertificate(std::string_view common_name) const;
};

// The least role that may call `method` (the full gRPC name,
// "/bsls.v1.CaptureDaemon/Grab"); kAdmin for methods this table does not know.
Role RequiredRole(std::string_view method);

}  // namespace bsls::service

#endif  // BSLS_SERVICE_ROLES_H_
