#include "halfback/util/atomic_file.hpp"
#include "halfback/util/output_dir.hpp"

#include "support/fifo_reader.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>

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

// docs/reliability/cli.md, "Files and outputs": a destination in a loop of symbolic links is
// refused (ELOOP, naming it) and the links stay links (it was replaced by a regular file, status
// 0); an output directory in a loop too.
TEST_F(AtomicFileTest, SymbolicLinkLoopIsRefusedAndKept) {
  const fs::path a = dir_ / "a.csv", b = dir_ / "b.csv", self = dir_ / "self.csv";
  fs::create_symlink("b.csv", a);
  fs::create_symlink("a.csv", b);
  fs::create_symlink("self.csv", self);
  for (const fs::path& target : {a, self}) {
    try {
      write_file_atomically(target, "new");
      ADD_FAILURE() << "no error for the loop " << target;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(target.filename().string()), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("symbolic links"), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(a)));
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(b)));
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(self)));
  EXPECT_EQ(entries(), (std::vector<std::string>{"a.csv", "b.csv", "self.csv"}));
  EXPECT_THROW(create_output_directory(self / "sub"), std::runtime_error);
}

TEST_F(AtomicFileTest, RelativePathInTheCurrentDirectory) {
  const fs::path cwd = fs::current_path();
  fs::current_path(dir_);
  write_file_atomically("plain.csv", "x");
  fs::current_path(cwd);
  EXPECT_EQ(slurp(dir_ / "plain.csv"), "x");
}

using test::FifoReader;

// Outputs that are not regular files (docs/reliability/cli.md, "Files and outputs"). A FIFO is
// written directly to its reader, and a probe (constructed, then discarded) does not open it:
// opening the writer end twice would give the reader an early end of file.
TEST_F(AtomicFileTest, FifoIsWrittenDirectlyAndKept) {
  const fs::path fifo = dir_ / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  { AtomicFile probe(fifo); }  // would block here if it opened the FIFO (no reader yet)
  FifoReader reader(fifo);
  {
    AtomicFile f(fifo);
    EXPECT_TRUE(f.direct());
    EXPECT_TRUE(f.temporary_path().empty());
    f.write("through ");
    f.write("the pipe");
    f.commit();
  }
  EXPECT_EQ(reader.finish(), "through the pipe");
  struct stat st {};
  ASSERT_EQ(::stat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  EXPECT_EQ(entries(), (std::vector<std::string>{"pipe"}));
}

// A character device is written, never renamed over (as root, renaming over /dev/null destroyed
// it). A private copy of /dev/null (mknod needs root) shows it without risking the real one.
TEST_F(AtomicFileTest, CharacterDeviceIsWrittenDirectlyAndKept) {
  const fs::path null = dir_ / "null";
  if (::mknod(null.c_str(), S_IFCHR | 0666, makedev(1, 3)) != 0)
    GTEST_SKIP() << "mknod needs root: " << std::strerror(errno);
  write_file_atomically(null, "discarded");
  struct stat st {};
  ASSERT_EQ(::stat(null.c_str(), &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode)) << "the device was replaced";
  EXPECT_EQ(st.st_rdev, makedev(1, 3));
  EXPECT_EQ(entries(), (std::vector<std::string>{"null"}));
}

// /dev/fd/N (like /dev/stdout) is that descriptor, written at its offset, not a file to replace.
TEST_F(AtomicFileTest, DescriptorPathIsWrittenDirectly) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  write_file_atomically("/dev/fd/" + std::to_string(fds[1]), "via the descriptor");
  ::close(fds[1]);
  char buf[64] = {};
  const ssize_t n = ::read(fds[0], buf, sizeof buf);
  ::close(fds[0]);
  EXPECT_EQ(std::string(buf, std::size_t(std::max<ssize_t>(n, 0))), "via the descriptor");
}

// A read-only regular file is refused like cp refuses it, even for root, and left as it was.
TEST_F(AtomicFileTest, ReadOnlyFileIsRefused) {
  const fs::path out = dir_ / "kept.csv";
  put(out, "precious");
  fs::permissions(out, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  try {
    write_file_atomically(out, "new");
    ADD_FAILURE() << "no exception";
  } catch (const std::system_error& e) {
    EXPECT_EQ(std::string(e.what()), "cannot write '" + out.string() +
                                         "' (it is read-only, mode 0444; make it writable or "
                                         "remove it): Permission denied");
  }
  EXPECT_EQ(slurp(out), "precious");
  EXPECT_EQ(entries(), (std::vector<std::string>{"kept.csv"}));
}

TEST_F(AtomicFileTest, SocketIsRefused) {
  const fs::path sock = dir_ / "s";
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  ASSERT_LT(sock.native().size(), sizeof addr.sun_path);
  std::strcpy(addr.sun_path, sock.c_str());
  ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr), 0);
  try {
    write_file_atomically(sock, "x");
    ADD_FAILURE() << "no exception";
  } catch (const std::system_error& e) {
    EXPECT_NE(std::string(e.what()).find("it is a socket"), std::string::npos) << e.what();
  }
  ::close(fd);
  EXPECT_TRUE(fs::is_socket(fs::symlink_status(sock)));
  EXPECT_EQ(entries(), (std::vector<std::string>{"s"}));
}

TEST_F(AtomicFileTest, DirectoryIsRefusedAndKept) {
  fs::create_directory(dir_ / "sub");
  put(dir_ / "sub" / "inside", "x");
  EXPECT_THROW(write_file_atomically(dir_ / "sub", "y"), std::system_error);
  EXPECT_EQ(slurp(dir_ / "sub" / "inside"), "x");
  EXPECT_EQ(entries(), (std::vector<std::string>{"sub"}));
}

// A folder for several outputs: parents created, an existing folder kept, and a file in the way
// named (not replaced).
TEST_F(AtomicFileTest, OutputDirectoryIsCreatedOrTheObstacleNamed) {
  const fs::path nested = dir_ / "a" / "b";
  create_output_directory(nested);
  EXPECT_TRUE(fs::is_directory(nested));
  create_output_directory(nested);  // already there: fine
  put(dir_ / "file", "keep");
  try {
    create_output_directory(dir_ / "file");
    ADD_FAILURE() << "no error for a file in the way";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot create the output directory"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("file"), std::string::npos) << e.what();
  }
  EXPECT_EQ(slurp(dir_ / "file"), "keep");
}

}  // namespace
}  // namespace halfback
