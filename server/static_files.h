#pragma once
/// \file static_files.h
/// The web page's files: finding the web root and mapping a URL path to a file inside it, with no
/// way out of the root (no "..", no symlink escape).

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace remeshd {

/// The web root: `option` if not empty; else REMESHD_DEFAULT_WEB_ROOT (the build's web/ folder)
/// if that directory exists; else <directory of the executable>/../web.
std::filesystem::path resolve_web_root(const std::string& option);

/// The file a URL path names inside `root` ("/" and directories -> index.html), or nullopt when
/// the path is invalid, escapes the root or names no regular file.
std::optional<std::filesystem::path> static_file(const std::filesystem::path& root, std::string_view url_path);

/// MIME type by extension (.html, .js, .mjs, .css, .svg, .json, .wasm, .map, .png, ...);
/// application/octet-stream when unknown.
std::string mime_for(const std::filesystem::path& file);

/// The page served at / when the web root is missing.
std::string missing_web_root_page(const std::filesystem::path& root);

}  // namespace remeshd
