// The corpus of malformed scenes, tests/io/bad_scenes/*.toml. Every file must fail to load with a
// SceneError (never a crash, never another exception) whose message is one line, begins with the
// file's name and contains the file's expected fragment: the text after "# expect: " on its first
// line, or, for files that cannot carry that line (empty, binary), the table below.

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gpa/io/scene_file.hpp"

namespace gpa::io {
namespace {

namespace fs = std::filesystem;

const fs::path corpus_dir = fs::path(GPA_IO_TEST_DIR) / "bad_scenes";

const std::map<std::string, std::string> expectations_without_header{
    {"empty.toml", "the file is empty"},
    {"binary_junk.toml", "is a control character: this is not a text file"},
    {"utf16.toml", "invalid UTF-8"},
};

std::vector<std::string> corpus_files() {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(corpus_dir)) {
        if (entry.path().extension() == ".toml") names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
}

std::string expected_fragment(const std::string& name) {
    const auto known = expectations_without_header.find(name);
    if (known != expectations_without_header.end()) return known->second;
    std::ifstream in(corpus_dir / name, std::ios::binary);
    std::string first_line;
    std::getline(in, first_line);
    const std::string marker = "# expect: ";
    if (first_line.rfind(marker, 0) != 0) return {};
    return first_line.substr(marker.size());
}

class BadScene : public ::testing::TestWithParam<std::string> {};

TEST_P(BadScene, FailsWithOneLineNamingFileAndProblem) {
    const std::string name = GetParam();
    const std::string expected = expected_fragment(name);
    ASSERT_FALSE(expected.empty()) << name << ": no \"# expect: \" line and no entry in the table";
    const fs::path path = corpus_dir / name;
    try {
        load_scene(path);
        FAIL() << name << " loaded without an error";
    } catch (const SceneError& e) {
        const std::string message = e.what();
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
        EXPECT_EQ(message.find('\r'), std::string::npos) << message;
        EXPECT_EQ(message.rfind(path.string(), 0), 0u) << "does not begin with the file: " << message;
        EXPECT_NE(message.find(expected), std::string::npos) << "expected \"" << expected << "\" in: " << message;
    } catch (const std::exception& e) {
        FAIL() << name << ": an exception other than SceneError: " << e.what();
    }
}

std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
    std::string out;
    for (const char c : info.param.substr(0, info.param.size() - 5)) {
        out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    }
    return out;
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadScene, ::testing::ValuesIn(corpus_files()), test_name);

TEST(BadSceneCorpus, HasAtLeastTwentyFiveFiles) { EXPECT_GE(corpus_files().size(), 25u); }

}  // namespace
}  // namespace gpa::io
