#include "halfback/util/atomic_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>

namespace halfback {
namespace {

namespace fs = std::filesystem;

class AtomicFileTest : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(testing::TempDir()) /
           ("atomic_file_test_" + std::to_string(getpid()) + "_" +
            testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(dir_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(dir_, ec);
  }

  static std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  static void put(const fs::path& p, const std::string& text) {
    std::ofstream(p, std::ios::binary) << text;
  }
  // The names in the directory, sorted.
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename());
    std::sort(names.begin(), names.end());
    return names;
  }

  fs::path dir_;
};

TEST_F(AtomicFileTest, CreatesTheFileOnCommitOnly) {
  const fs::path out = dir_ / "out.csv";
  {
    AtomicFile f(out);
    f.write("hello, ");
    f.write("world\n");
    EXPECT_FALSE(fs::exists(out));  // nothing visible before the commit
    EXPECT_TRUE(fs::exists(f.temporary_path()));
    EXPECT_EQ(f.temporary_path().parent_path(), out.parent_path());
    f.commit();
    EXPECT_TRUE(f.committed());
  }
  EXPECT_EQ(slurp(out), "hello, world\n");
  EXPECT_EQ(entries(), (std::vector<std::string>{"out.csv"}));
}

TEST_F(AtomicFileTest, ReplacesAnExistingFile) {
  const fs::path out = dir_ / "out.csv";
  put(out, "old");
  write_file_atomically(out, "new");
  EXPECT_EQ(slurp(out), "new");
  EXPECT_EQ(entries(), (std::vector<std::string>{"out.csv"}));
}

TEST_F(AtomicFileTest, WithoutCommitNothingChanges) {
  const fs::path out = dir_ / "out.csv", fresh = dir_ / "fresh.csv";
  put(out, "precious");
  {
    AtomicFile f(out);
    f.write("partial");
  }
  try {
    AtomicFile f(fresh);
    f.write("partial");
    throw std::runtime_error("bad input");
  } catch (const std::runtime_error&) {
  }
  {
    AtomicFile f(out);
    f.write("partial");
    f.discard();
    EXPECT_THROW(f.write("more"), std::system_error);
    EXPECT_THROW(f.commit(), std::system_error);
  }
  EXPECT_EQ(slurp(out), "precious");
  EXPECT_FALSE(fs::exists(fresh));
  EXPECT_EQ(entries(), (std::vector<std::string>{"out.csv"}));
}

TEST_F(AtomicFileTest, CommitTwiceThrows) {
  AtomicFile f(dir_ / "out.csv");
  f.commit();
  EXPECT_THROW(f.commit(), std::system_error);
  EXPECT_EQ(slurp(dir_ / "out.csv"), "");
}

TEST_F(AtomicFileTest, MissingDirectory) {
  const fs::path out = dir_ / "no" / "such" / "out.csv";
  try {
    AtomicFile f(out);
    ADD_FAILURE() << "no exception";
  } catch (const std::system_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "cannot write '" + out.string() + "': No such file or directory");
  }
}

TEST_F(AtomicFileTest, UnwritableDirectory) {
  if (geteuid() == 0) GTEST_SKIP() << "root ignores directory permissions";
  const fs::path sub = dir_ / "ro", out = sub / "out.csv";
  fs::create_directory(sub);
  put(out, "precious");
  fs::permissions(sub, fs::perms::owner_read | fs::perms::owner_exec);
  try {
    AtomicFile f(out);
    ADD_FAILURE() << "no exception";
  } catch (const std::system_error& e) {
    EXPECT_EQ(std::string(e.what()), "cannot write '" + out.string() + "': Permission denied");
  }
  fs::permissions(sub, fs::perms::owner_all);
  EXPECT_EQ(slurp(out), "precious");
}

TEST_F(AtomicFileTest, ParentIsAFile) {  // fails even for root
  put(dir_ / "file", "precious");
  const fs::path out = dir_ / "file" / "out.csv";
  try {
    AtomicFile f(out);
    ADD_FAILURE() << "no exception";
  } catch (const std::system_error& e) {
    EXPECT_EQ(std::string(e.what()), "cannot write '" + out.string() + "': Not a directory");
  }
  EXPECT_EQ(slurp(dir_ / "file"), "precious");
}

TEST_F(AtomicFileTest, TargetIsADirectory) {
  try {
    AtomicFile f(dir_);
    ADD_FAILURE() << "no exception";
  } catch (const std::system_error& e) {
    EXPECT_EQ(std::string(e.what()), "cannot write '" + dir_.string() + "': Is a directory");
  }
  EXPECT_THROW(AtomicFile f(""), std::system_error);
}

TEST_F(AtomicFileTest, Permissions) {
  const fs::path out = dir_ / "out.csv", kept = dir_ / "kept.csv";
  const mode_t mask = ::umask(022);
  ::umask(mask);
  write_file_atomically(out, "x");
  struct stat st {};
  ASSERT_EQ(::stat(out.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0666 & ~mask);

  put(kept, "old");
  fs::permissions(kept, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  write_file_atomically(kept, "new");
  ASSERT_EQ(::stat(kept.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u);
}

TEST_F(AtomicFileTest, SymbolicLinkIsKept) {
  const fs::path real = dir_ / "real.csv", link = dir_ / "link.csv";
  put(real, "old");
  fs::create_symlink("real.csv", link);
  write_file_atomically(link, "new");
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link)));
  EXPECT_EQ(slurp(real), "new");
  EXPECT_EQ(entries(), (std::vector<std::string>{"link.csv", "real.csv"}));
}

TEST_F(AtomicFileTest, RelativePathInTheCurrentDirectory) {
  const fs::path cwd = fs::current_path();
  fs::current_path(dir_);
  write_file_atomically("plain.csv", "x");
  fs::current_path(cwd);
  EXPECT_EQ(slurp(dir_ / "plain.csv"), "x");
}

}  // namespace
}  // namespace halfback
