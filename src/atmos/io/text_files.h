// atmos: whole-file reads and the text encodings of files written for the web
// (`atmos viewer`'s scripts).
#pragma once

#include <filesystem>
#include <string>

namespace atmos {

// The bytes of a file (atmos::Error naming it when it cannot be read).
std::string ReadWholeFile(const std::filesystem::path& path);

// A JavaScript string literal of `text` (quoted; ", \ and newlines escaped,
// carriage returns dropped, '<' as \x3c so that no "</script>" ends a script).
std::string JsStringLiteral(const std::string& text);

// Base64 (RFC 4648 section 4, with '=' padding) of `bytes`.
std::string Base64Encode(const std::string& bytes);

}  // namespace atmos
