// The manual page (vmpray --manpage) and the bash completion (vmpray
// --completion bash) against what --help lists: the page names every option
// of both commands in their sections and nothing else, its examples parse,
// it renders without a warning; the script, run in bash as the shell would
// run it, offers every option and the words an option takes. And --version
// says how the binary was built.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "app/experiments/sweep.hpp"
#include "tests/support/command_line.hpp"
#include "tests/support/scratch.hpp"

namespace {

using test::Outcome;
using Names = std::set<std::string>;

// "--output" and "-o" for each option --help lists as "  -o [ --output ] arg"
// or "  --stats arg" (continuation lines are indented further).
Names help_options(const std::string& help) {
  Names names;
  const std::regex option(R"(^  (?:-([A-Za-z]) \[ )?--([a-z0-9][a-z0-9-]*))");
  std::istringstream lines(help);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (!std::regex_search(line, m, option)) continue;
    names.insert("--" + m[2].str());
    if (m[1].matched) names.insert("-" + m[1].str());
  }
  return names;
}

// The page's text from ".SH title" to the next section.
std::string section(const std::string& page, const std::string& title) {
  const std::size_t start = page.find(".SH " + title + "\n");
  if (start == std::string::npos) return "";
  return page.substr(start, page.find("\n.SH ", start + 1) - start);
}

// Roff's escapes back to the characters they stand for.
std::string unroff(std::string text) {
  for (const auto& [escape, plain] : {std::pair{"\\-", "-"}, {"\\(aq", "'"}, {"\\e", "\\"}, {"\\fB", ""}, {"\\fR", ""}})
    for (std::size_t at; (at = text.find(escape)) != std::string::npos;) text.replace(at, std::string(escape).size(), plain);
  return text;
}

// The options a section's ".TP" headings name: "\fB\-o\fR, \fB\-\-output\fR \fIarg\fR".
Names page_options(const std::string& text) {
  Names names;
  const std::regex option(R"(\\fB((?:\\-)+[A-Za-z0-9](?:[a-z0-9]|\\-)*)\\fR)");
  std::istringstream lines(text);
  bool heading = false;
  for (std::string line; std::getline(lines, line); heading = line == ".TP") {
    if (!heading) continue;
    for (std::sregex_iterator m(line.begin(), line.end(), option), end; m != end; ++m)
      names.insert(unroff((*m)[1].str()));
  }
  return names;
}

class ManualCli : public test::ScratchTest {
 protected:
  ManualCli() : ScratchTest("vmpray_manual_") {}
  std::string output_of(const std::string& args) {
    const Outcome r = run_vmpray(args);
    EXPECT_EQ(r.exit_code, 0) << args << ": " << r.err;
    EXPECT_EQ(r.err, "") << args;
    return r.out;
  }
  // What bash's completion offers for `words`, the last being the word at
  // the cursor, as the shell calls _vmpray after sourcing the script.
  Names complete(const std::vector<std::string>& words) {
    std::ofstream script(dir_ / "ask.sh");
    script << "source ./completion.bash\nCOMP_WORDS=(";
    for (const std::string& word : words) script << " '" << word << "'";
    script << ")\nCOMP_CWORD=" << words.size() - 1 << "\n_vmpray\nprintf '%s\\n' \"${COMPREPLY[@]}\"\n";
    script.close();
    const std::string cmd = "cd '" + dir_.string() + "' && bash --norc --noprofile ask.sh >reply.txt";
    EXPECT_EQ(std::system(cmd.c_str()), 0);
    Names offered;
    std::istringstream lines(test::read_file(dir_ / "reply.txt"));
    for (std::string line; std::getline(lines, line);)
      if (!line.empty()) offered.insert(line);
    return offered;
  }
};

TEST_F(ManualCli, ThePageNamesEveryOptionOfBothCommandsAndNoOther) {
  const std::string page = output_of("--manpage");
  const Names render = help_options(output_of("--help")), sweep = help_options(output_of("sweep --help"));
  EXPECT_GT(render.size(), 30u);
  EXPECT_GT(sweep.size(), 15u);
  EXPECT_EQ(page_options(section(page, "OPTIONS")), render);
  EXPECT_EQ(page_options(section(page, "SWEEP")), sweep);
  const Names network = help_options(output_of("network --help"));
  EXPECT_GT(network.size(), 10u);
  EXPECT_EQ(page_options(section(page, "NETWORK")), network);
  EXPECT_EQ(render.count("--manpage") + render.count("--completion"), 0u) << "hidden options stay out of --help";
  for (const char* title : {"NAME", "SYNOPSIS", "DESCRIPTION", "\"BUILT\\-IN SCENES\"", "EXAMPLES", "\"SEE ALSO\""})
    EXPECT_NE(section(page, title), "") << title;
  EXPECT_NE(section(page, "\"SEE ALSO\"").find(".BR mpirun (1)"), std::string::npos);
  EXPECT_EQ(page.rfind(".TH VMPRAY 1 ", 0), 0u);
}

TEST_F(ManualCli, ThePageExamplesParse) {
  const std::string examples = section(output_of("--manpage"), "EXAMPLES");
  std::istringstream lines(examples);
  int parsed = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("\\fB", 0) != 0) continue;
    std::string command = unroff(line);
    command = command.substr(command.find("vmpray"));  // after "mpirun -np 4"
    SCOPED_TRACE(command);
    std::istringstream in(command);
    std::vector<std::string> words;
    for (std::string word; in >> word;) words.push_back(word);
    std::vector<const char*> args;
    for (const std::string& word : words) args.push_back(word.c_str());
    if (words.size() > 1 && words[1] == "sweep")
      EXPECT_NO_THROW(app::parse_sweep_options(static_cast<int>(args.size()) - 1, args.data() + 1));
    else
      EXPECT_NO_THROW(test::parse(std::vector<const char*>(args.begin() + 1, args.end())));
    ++parsed;
  }
  EXPECT_GE(parsed, 5);
}

TEST_F(ManualCli, ThePageRendersWithoutWarnings) {
  if (std::system("command -v man >/dev/null 2>&1") != 0) GTEST_SKIP() << "man (man-db) is not installed";
  run_vmpray("--manpage", "vmpray.1");
  const std::string cmd = "cd '" + dir_.string() + "' && MANWIDTH=80 man --warnings -l vmpray.1 >page.txt 2>warnings.txt";
  EXPECT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_EQ(test::read_file(dir_ / "warnings.txt"), "");
  EXPECT_NE(test::read_file(dir_ / "page.txt").find("--cache-pages"), std::string::npos);
}

TEST_F(ManualCli, TheCompletionOffersEveryOptionAndTheTopologyKinds) {
  ASSERT_EQ(run_vmpray("--completion bash", "completion.bash").exit_code, 0);
  const Names render = help_options(output_of("--help")), sweep = help_options(output_of("sweep --help"));
  EXPECT_EQ(complete({"vmpray", "-"}), render);
  EXPECT_EQ(complete({"vmpray", "sweep", "nodes", "-"}), sweep);
  EXPECT_EQ(complete({"vmpray", "--to"}), Names{"--topology"});
  const Names kinds{"hypercube", "mesh", "torus", "ring", "complete"};
  EXPECT_EQ(complete({"vmpray", "--topology", ""}), kinds);
  EXPECT_EQ(complete({"vmpray", "sweep", "cache", "--topology", ""}), kinds);
  EXPECT_EQ(complete({"vmpray", "--schedule", ""}), (Names{"affinity", "dynamic", "static"}));
  EXPECT_EQ(complete({"vmpray", "network", "-"}), help_options(output_of("network --help")));
  EXPECT_EQ(complete({"vmpray", "network", "--pattern", "b"}), (Names{"bit-complement", "bit-reversal"}));
  EXPECT_EQ(complete({"vmpray", "network", "--topology", "to"}), Names{"torus"});
}

TEST_F(ManualCli, TheCompletionOffersSubcommandScenesAndFiles) {
  ASSERT_EQ(run_vmpray("--completion bash", "completion.bash").exit_code, 0);
  std::ofstream(dir_ / "scene.nff") << "";
  EXPECT_EQ(complete({"vmpray", "sw"}), Names{"sweep"});
  EXPECT_EQ(complete({"vmpray", "netw"}), Names{"network"});
  EXPECT_EQ(complete({"vmpray", "sweep", ""}), (Names{"nodes", "cache"}));
  EXPECT_EQ(complete({"vmpray", "tetra"}), (Names{"tetra", "tetra9", "tetra10"}));
  EXPECT_EQ(complete({"vmpray", "sc"}), Names{"scene.nff"});
  EXPECT_EQ(complete({"vmpray", "--single", "-o", "sc"}), Names{"scene.nff"});
  EXPECT_EQ(complete({"vmpray", "--nodes", ""}), Names{}) << "a number: nothing to offer";
  EXPECT_EQ(complete({"vmpray", "sweep", "nodes", "--scene", "rings"}), (Names{"rings", "rings4"}));
}

TEST_F(ManualCli, CompletionForAnotherShellIsAUsageError) {
  const Outcome r = run_vmpray("--completion zsh");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--completion: expected bash, got 'zsh'"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
}

TEST_F(ManualCli, VersionSaysHowTheBinaryWasBuilt) {
  const std::string version = output_of("--version");
  EXPECT_EQ(version.rfind("vmpray " VMPRAY_VERSION "\n", 0), 0u) << version;
  EXPECT_TRUE(std::regex_search(version, std::regex("\ncompiler: (GCC|clang) [0-9]"))) << version;
  EXPECT_TRUE(std::regex_search(version, std::regex("\nbuild type: [A-Za-z]+\n"))) << version;
}

}  // namespace
