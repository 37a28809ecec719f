// The one error of the contract conversions: a message that protobuf
// accepted but that does not describe usable input (a frame whose pixels
// do not fill it, an enum number its .proto does not define, a distance
// with three points). The services answer it with INVALID_ARGUMENT.
#ifndef BSLS_CONTRACT_MESSAGE_ERROR_H_
#define BSLS_CONTRACT_MESSAGE_ERROR_H_

#include <stdexcept>

namespace bsls::contract {

// what() names the field (as the request spells it) and the reason.
class MessageError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

}  // namespace bsls::contract

#endif  // BSLS_CONTRACT_MESSAGE_ERROR_H_
