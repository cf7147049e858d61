#include "halfback/figure/scene.hpp"

namespace halfback::figure {

std::vector<TextRun> parse_markup(std::string_view s) {
  std::vector<TextRun> runs;
  auto append = [&](int script, std::string_view piece) {
    if (piece.empty()) return;
    if (!runs.empty() && runs.back().script == script)
      runs.back().text += piece;
    else
      runs.push_back({std::string(piece), script});
  };
  std::size_t i = 0;
  while (i < s.size()) {
    const char c = s[i];
    if (c == '\\' && i + 1 < s.size() && (s[i + 1] == '_' || s[i + 1] == '^')) {
      append(0, s.substr(i + 1, 1));
      i += 2;
    } else if ((c == '_' || c == '^') && i + 1 < s.size()) {
      const int script = c == '_' ? -1 : 1;
      if (s[i + 1] == '{') {
        const std::size_t close = s.find('}', i + 2);
        const std::size_t end = close == std::string_view::npos ? s.size() : close;
        append(script, s.substr(i + 2, end - (i + 2)));
        i = close == std::string_view::npos ? s.size() : close + 1;
      } else {
        // One UTF-8 character, with any combining marks that follow it (U+0300–U+036F).
        std::size_t j = i + 2;
        auto continuation = [&](std::size_t k) { return k < s.size() && (s[k] & 0xC0) == 0x80; };
        while (continuation(j)) ++j;
        auto combining = [&](std::size_t k) {
          if (k + 1 >= s.size()) return false;
          const auto b0 = static_cast<unsigned char>(s[k]),
                     b1 = static_cast<unsigned char>(s[k + 1]);
          return b0 == 0xCC || (b0 == 0xCD && b1 <= 0xAF);
        };
        while (combining(j)) j += 2;
        append(script, s.substr(i + 1, j - (i + 1)));
        i = j;
      }
    } else {
      append(0, s.substr(i, 1));
      ++i;
    }
  }
  return runs;
}

std::string plain_text(std::string_view text) {
  std::string out;
  for (const TextRun& r : parse_markup(text)) out += r.text;
  return out;
}

std::string escape_markup(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '_' || c == '^') out += '\\';
    out += c;
  }
  return out;
}

void Scene::add(Item item) {
  items.push_back(std::move(item));
}

void append_scene(Scene& dst, const Scene& src, Point offset) {
  auto move = [&](Point& p) {
    p.x += offset.x;
    p.y += offset.y;
  };
  for (Item item : src.items) {
    if (auto* path = std::get_if<PathItem>(&item))
      for (Point& p : path->points) move(p);
    else if (auto* circle = std::get_if<CircleItem>(&item))
      move(circle->centre);
    else if (auto* image = std::get_if<ImageItem>(&item))
      image->x += offset.x, image->y += offset.y;
    else if (auto* text = std::get_if<TextItem>(&item))
      move(text->at);
    dst.add(std::move(item));
  }
}

double baseline_offset(VAlign v) {
  switch (v) {
    case VAlign::middle:
      return 0.36;
    case VAlign::top:
      return 0.74;
    case VAlign::bottom:
      return -0.24;
    case VAlign::baseline:
      break;
  }
  return 0.0;
}

}  // namespace halfback::figure
