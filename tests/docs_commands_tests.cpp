// The command lines the README and docs/ show: every option they name is an option of that
// subcommand, and every example that names real files runs (exit 0) in a folder laid out like
// the repository, smaller: pictures at 48 px, videos at 2 frames a second, one small pick. Viewer
// and bench lines are only checked for their options (the window suite drives the viewer; the
// bench tests run each bench).
#include <doctest/doctest.h>

#include <glob.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "gpu_fixture.h"
#include "test_files.h"

namespace strata {
namespace {

namespace fs = std::filesystem;
using test::run_strata;

const fs::path source = STRATA_SOURCE_DIR;

struct DocCommand {
  std::string where;  // "README.md:12"
  std::string text;   // after "strata ", comments dropped, continued lines joined
  std::string run;    // the example itself: text without the "[--option]" lines under it
};

// "strata ..." lines of ```sh blocks (a line ending in '\' or followed by indented "[--option"
// lines goes on) and `strata ...` spans of the prose.
std::vector<DocCommand> doc_commands(const fs::path& page) {
  std::vector<DocCommand> out;
  std::istringstream in(test::read_file(page));
  const std::string name = page.lexically_relative(source).string();
  bool block = false, shell = false, continued = false;
  size_t number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    if (line.starts_with("```")) {
      shell = !block && line == "```sh";
      block = !block;
      continued = false;
      continue;
    }
    if (block) {
      if (!shell) continue;
      const std::string code = line.substr(0, line.find(" # "));
      const size_t first = code.find_first_not_of(' ');
      const bool options = first != std::string::npos && code.compare(first, 3, "[--") == 0;
      if (continued || (options && !out.empty() && out.back().where.starts_with(name + ":"))) {
        out.back().text += " " + code.substr(first);
        if (continued) out.back().run += " " + code.substr(first);
      } else if (code.starts_with("strata ")) {
        out.push_back({name + ":" + std::to_string(number), code.substr(7), code.substr(7)});
      } else {
        continued = false;
        continue;
      }
      continued = !out.back().text.empty() && out.back().text.back() == '\\';
      if (continued) out.back().text.pop_back(), out.back().run.pop_back();
      continue;
    }
    static const std::regex span("`strata ([^`]+)`");
    for (std::sregex_iterator m(line.begin(), line.end(), span), end; m != end; ++m) {
      std::string text = (*m)[1].str();
      for (size_t bar; (bar = text.find("\\|")) != std::string::npos;) text.erase(bar, 1);
      out.push_back({name + ":" + std::to_string(number), text, text});
    }
  }
  return out;
}

// Words as the shell splits them, a "quoted phrase" one word (its quotes kept, for the shell that
// runs it).
std::vector<std::string> words(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> out;
  bool quoted = false;
  for (std::string w; in >> w;) {
    if (quoted) {
      out.back() += " " + w;
    } else {
      out.push_back(w);
    }
    quoted ^= std::count(w.begin(), w.end(), '"') % 2 == 1;
  }
  return out;
}

// `strata [COMMAND [SUB]] --help`, read once each.
const std::string& help(const std::string& command) {
  static std::map<std::string, std::string> cache;
  auto [it, added] = cache.try_emplace(command);
  if (added) {
    const auto r = run_strata(command + " --help");
    REQUIRE_MESSAGE(r.exit_code == 0, "strata " << command << " --help: " << r.output);
    it->second = r.output;
  }
  return it->second;
}

bool lists_option(const std::string& help_text, const std::string& option) {
  return std::regex_search(help_text, std::regex("[ ,]" + option + "[ ,=\n]"));
}

// An example to run: its subcommand runs here, and every file it reads is in the repository.
bool runnable(const std::vector<std::string>& w, const fs::path& folder) {
  static const std::set<std::string> commands = {"render", "video", "pick",
                                                 "info",   "eval",  "devices"};
  static const std::set<std::string> outputs = {"-o",           "--output",      "--layout",
                                                "--layout-dir", "--dump-layers", "--still-layouts"};
  static const std::regex placeholder(R"([A-Z][A-Z0-9_]*(\.\.\.)?|.*(\||\.\.\.|\[|\]).*)");
  if (w.empty() || !commands.contains(w[0])) return false;
  size_t inputs = 0;  // (a span such as `strata render --camera` names an option, not an example)
  for (size_t i = 1; i < w.size(); ++i) {
    if (std::regex_match(w[i], placeholder)) return false;
    const bool path = w[i].find('/') != std::string::npos || w[i].ends_with(".json") ||
                      w[i].ends_with(".gz") || w[i].ends_with(".fcsv");
    if (outputs.contains(w[i - 1])) {  // (written: its folder made, never into the repository)
      CHECK_MESSAGE(!(w[i].starts_with("assets/") || w[i].starts_with("tests/")),
                    w[i] << " would be written into the repository");
      if (w[i].find('/') != std::string::npos && !w[i].starts_with("/"))
        fs::create_directories((folder / w[i]).parent_path());
      continue;
    }
    if (!path || w[i].starts_with("-")) continue;
    glob_t found{};
    const int status = glob((folder / w[i]).c_str(), 0, nullptr, &found);
    globfree(&found);
    if (status != 0) {
      // A file of the reader's own (/usr/local/..., scan.nii.gz), or a placeholder under the
      // repository's folders (assets/scenes/SCENE.json); else the page names a file we lack.
      static const std::regex named_by_reader(R"((^|/)[A-Z]+(\.|$))");
      const bool ours =
          w[i].starts_with("assets/") || w[i].starts_with("tests/") || w[i].starts_with("docs/");
      CHECK_MESSAGE((!ours || std::regex_search(w[i], named_by_reader)),
                    w[i] << " is not in the repository");
      return false;
    }
    ++inputs;
  }
  if (inputs == 0 && w[0] != "devices") return false;
#if !STRATA_VIDEO
  for (const std::string& word : w)
    if (word.ends_with(".mp4")) return false;
#endif
  return true;
}

// The example made small: pictures at 48 px, videos at 2 frames a second, picks run once an eighth
// as wide; what it writes goes to the working folder.
std::string made_small(std::vector<std::string> w) {
  const bool picture = w[0] == "render" || w[0] == "video";
  bool sized = false;
  // A pick's picture an eighth as wide (512 px where none is given), its pixels with it.
  const auto scaled = [](const std::string& pair, char separator) {
    const size_t at = pair.find(separator);
    const auto eighth = [](const std::string& n) { return std::to_string(std::stoi(n) / 8); };
    return at == std::string::npos
               ? eighth(pair)
               : eighth(pair.substr(0, at)) + separator + eighth(pair.substr(at + 1));
  };
  for (size_t i = 1; i + 1 < w.size(); ++i) {
    if (picture && w[i] == "--size") w[i + 1] = "48", sized = true;
    if (w[0] == "video" && w[i] == "--fps") w[i + 1] = "2";
    if (w[0] == "pick" && w[i] == "--runs") w[i + 1] = "1";
    if (w[0] == "pick" && w[i] == "--size") w[i + 1] = scaled(w[i + 1], 'x'), sized = true;
    if (w[0] == "pick" && w[i] == "--at") w[i + 1] = scaled(w[i + 1], ',');
    if (w[i] == "-o" && w[i + 1].starts_with("/tmp/")) w[i + 1].erase(0, 5);  // into the folder
  }
  if (picture && !sized) w.insert(w.end(), {"--size", "48"});
  if (w[0] == "pick" && !sized) w.insert(w.end(), {"--size", "64"});
  std::string text;
  for (const std::string& word : w) text += (text.empty() ? "" : " ") + word;
  return text;
}

}  // namespace

TEST_SUITE("cli") {
  TEST_CASE("the_readme_and_docs_command_lines_name_real_options_and_their_examples_run") {
    const fs::path folder = test::fresh_folder("docs_commands", "work");
    // (the repository's inputs linked in; what an example writes stays in the folder)
    for (const char* linked : {"assets", "tests"})
      fs::create_directory_symlink(source / linked, folder / linked);
    std::vector<fs::path> pages = {source / "README.md"};
    for (const auto& entry : fs::directory_iterator(source / "docs"))
      if (entry.path().extension() == ".md") pages.push_back(entry.path());
    std::sort(pages.begin() + 1, pages.end());

    size_t commands = 0, options = 0;
    std::set<std::string> ran;
    for (const fs::path& page : pages) {
      for (const DocCommand& c : doc_commands(page)) {
        CAPTURE(c.where);
        CAPTURE(c.text);
        const std::vector<std::string> w = words(c.text);
        size_t at = 0;
        while (at < w.size() && w[at].starts_with("-")) {  // strata's own: --validate
          CHECK_MESSAGE(lists_option(help(""), w[at]), "strata has no option " << w[at]);
          ++at;
        }
        if (at == w.size()) continue;  // `strata --validate`
        std::vector<std::string> subcommands;
        std::istringstream names(w[at]);
        for (std::string name; std::getline(names, name, '|');) subcommands.push_back(name);
        if (subcommands == std::vector<std::string>{"COMMAND"}) continue;
        if (subcommands.size() == 1 && subcommands[0] == "bench" && at + 1 < w.size() &&
            !w[at + 1].starts_with("-")) {
          subcommands.clear();
          std::istringstream benches(w[at + 1]);
          for (std::string name; std::getline(benches, name, '|');)
            subcommands.push_back("bench " + name);
        }
        ++commands;
        for (const std::string& sub : subcommands) {
          const std::string& text = help(sub);
          for (size_t i = at + 1; i < w.size(); ++i) {
            static const std::regex option(R"((?:^|[\[|])(--?[a-z][a-z0-9-]*))");
            std::smatch m;
            if (!std::regex_search(w[i], m, option)) continue;
            CHECK_MESSAGE(lists_option(text, m[1].str()),
                          "strata " << sub << " has no option " << m[1].str());
            ++options;
          }
        }
        std::vector<std::string> command = words(c.run);
        command.erase(command.begin(), command.begin() + long(at));
        if (!runnable(command, folder)) continue;
        const std::string small = made_small(command);
        if (!ran.insert(small).second) continue;
        const auto r = run_strata(small, "cd '" + folder.string() + "' &&");
        CAPTURE(small);
        CAPTURE(r.output);
        CHECK(r.exit_code == 0);
      }
    }
    MESSAGE(commands << " command lines, " << options << " options checked, " << ran.size()
                     << " examples run");
    CHECK(commands > 100);
    CHECK(ran.size() >= 15);
  }
}

}  // namespace strata
