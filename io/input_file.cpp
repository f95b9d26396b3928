#include "io/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/model/limits.hpp"

namespace femdyn {

std::string read_input_file(const std::string& path) {
  // A C++ or Python caller may pass one; the system would open only the part before it.
  if (path.find('\0') != std::string::npos)
    throw ModelError(path, "the path contains a NUL character");
  // O_NONBLOCK: opening a FIFO without a writer returns at once instead of waiting for one.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw ModelError(path, std::string("cannot open file: ") + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0)
    throw ModelError(path, std::string("cannot read file: ") + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) throw ModelError(path, "is a directory, not a file");
  if (!S_ISREG(st.st_mode))
    throw ModelError(path,
                     "is not a regular file (a FIFO, device or socket): femdyn reads files only");
  if (st.st_size > kMaxFileBytes)
    throw ModelError(path, "is " + std::to_string(st.st_size) + " bytes: more than the limit of " +
                               std::to_string(kMaxFileBytes) + " bytes for an input file");
  std::string text(static_cast<std::size_t>(st.st_size), '\0');
  std::size_t got = 0;
  while (got < text.size()) {
    const ssize_t r = ::read(fd, text.data() + got, text.size() - got);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) throw ModelError(path, std::string("cannot read file: ") + std::strerror(errno));
    if (r == 0) break;  // shrank while reading
    got += static_cast<std::size_t>(r);
  }
  text.resize(got);
  return text;
}

}  // namespace femdyn
