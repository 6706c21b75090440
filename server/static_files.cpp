#include "static_files.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <map>

namespace remeshd {

namespace fs = std::filesystem;

fs::path resolve_web_root(const std::string& option) {
  if (!option.empty()) return fs::path(option);
#ifdef REMESHD_DEFAULT_WEB_ROOT
  {
    std::error_code ec;
    fs::path built(REMESHD_DEFAULT_WEB_ROOT);
    if (fs::is_directory(built, ec)) return built;
  }
#endif
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return fs::path("web");
  return (exe.parent_path() / ".." / "web").lexically_normal();
}

std::optional<fs::path> static_file(const fs::path& root, std::string_view url_path) {
  if (url_path.empty() || url_path.front() != '/' || url_path.size() > 1024) return std::nullopt;
  fs::path rel;
  std::size_t i = 1;
  while (i <= url_path.size()) {
    std::size_t j = url_path.find('/', i);
    if (j == std::string_view::npos) j = url_path.size();
    std::string_view seg = url_path.substr(i, j - i);
    if (!seg.empty()) {
      if (seg == "." || seg == ".." || seg.front() == '.') return std::nullopt;  // no dot files either
      for (char c : seg)
        if (c == '\\' || c == '\0' || static_cast<unsigned char>(c) < 0x20) return std::nullopt;
      rel /= std::string(seg);
    }
    i = j + 1;
  }
  std::error_code ec;
  fs::path canonical_root = fs::canonical(root, ec);
  if (ec) return std::nullopt;
  fs::path candidate = canonical_root / rel;
  if (fs::is_directory(candidate, ec)) candidate /= "index.html";
  else if (url_path.back() == '/') return std::nullopt;  // a file named as a directory (/style.css/)
  fs::path real = fs::canonical(candidate, ec);
  if (ec || !fs::is_regular_file(real, ec)) return std::nullopt;
  // Symlinks must not lead out of the root.
  auto [r, c] = std::mismatch(canonical_root.begin(), canonical_root.end(), real.begin(), real.end());
  if (r != canonical_root.end()) return std::nullopt;
  return real;
}

std::string mime_for(const fs::path& file) {
  static const std::map<std::string, std::string> types = {
      {".html", "text/html; charset=utf-8"},
      {".htm", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".svg", "image/svg+xml"},
      {".json", "application/json"},
      {".map", "application/json"},
      {".wasm", "application/wasm"},
      {".png", "image/png"},
      {".jpg", "image/jpeg"},
      {".ico", "image/x-icon"},
      {".txt", "text/plain; charset=utf-8"},
      {".woff2", "font/woff2"},
      {".glb", "model/gltf-binary"},
      {".obj", "model/obj"},
      {".yaml", "application/yaml"},
  };
  std::string ext = file.extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  auto it = types.find(ext);
  return it == types.end() ? "application/octet-stream" : it->second;
}

std::string missing_web_root_page(const fs::path& root) {
  std::string r = root.string();
  std::string escaped;
  for (char c : r) {
    if (c == '<') escaped += "&lt;";
    else if (c == '>') escaped += "&gt;";
    else if (c == '&') escaped += "&amp;";
    else escaped += c;
  }
  return "<!doctype html><html><head><meta charset=\"utf-8\"><title>remeshd</title></head><body>"
         "<h1>remeshd is running</h1><p>The web page is not installed: no web root at <code>" +
         escaped +
         "</code>. Build the <code>web</code> target or start remeshd with <code>--web-root DIR</code>.</p>"
         "<p>The API is at <a href=\"/api/v1/openapi.yaml\">/api/v1/openapi.yaml</a>; health at "
         "<a href=\"/healthz\">/healthz</a>.</p></body></html>";
}

}  // namespace remeshd
