// Grammars for the parser fuzz targets: each turns a recipe (FuzzInput) into
// a document of its format that is structurally valid, or nearly so, so that
// the fuzzer gets past the first syntax check into the code behind it. Every
// grammar also makes the format's hostile shapes on purpose: YAML anchors,
// aliases to themselves and to their ancestors, nesting beyond the limits;
// PLY element counts far above the bytes that follow; PNG headers claiming
// huge sizes with a correct CRC; OBJ faces naming vertices not defined.
//
// An exhausted recipe reads as zeros, which every grammar maps to its plain
// choice (the template unchanged, the smallest valid file).
//
// Thread-safety: pure functions.
#ifndef BSLS_TESTS_FUZZ_GRAMMARS_H_
#define BSLS_TESTS_FUZZ_GRAMMARS_H_

#include <string>
#include <vector>

#include "fuzz_input.h"

namespace bsls::fuzz {

// A YAML document: one of `templates` (parsed YAML texts without aliases;
// the recipe picks which) with its nodes kept, replaced, deleted, repeated,
// nested deeper, anchored or turned into aliases as the recipe says, and
// written in block or flow style. With no template a document is made from
// nothing, its keys taken from `keys`.
std::string YamlFrom(FuzzInput& in, const std::vector<std::string>& templates,
                     const std::vector<std::string>& keys);

// A PLY file: ascii or binary header with elements (vertex, face, others)
// whose counts and properties the recipe chooses, then a body of values of
// those types for at most a few dozen items each, possibly cut short or
// followed by junk.
std::string PlyFrom(FuzzInput& in);

// A Wavefront OBJ file: v, vn, vt, f (with a, a/b, a//c, a/b/c and negative
// references), comments and other statements, numbers sometimes absurd.
std::string ObjFrom(FuzzInput& in);

// A PNG file: the signature, an IHDR (size, bit depth and colour type from
// the recipe, from the valid ones mostly, with a correct CRC mostly), PLTE
// and tRNS when the colour type wants them, IDAT of zlib-compressed scan
// lines (filter bytes included) for up to 64 rows, sometimes cut short, IEND.
// One recipe in eight makes a PNM (P2, P3, P5, P6) of any size instead.
std::string PngFrom(FuzzInput& in);

// A JSON document: objects and arrays nested as the recipe says (deeper than
// any real file), keys of the evaluate command's files, numbers sometimes absurd.
std::string JsonFrom(FuzzInput& in);

}  // namespace bsls::fuzz

#endif  // BSLS_TESTS_FUZZ_GRAMMARS_H_
