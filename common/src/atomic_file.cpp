// Files written whole or not at all (atomic_file.h).
#include "atonlab/common/atomic_file.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <random>
#include <system_error>
#include <utility>

namespace atonlab::files {
namespace fs = std::filesystem;

namespace {

std::string errno_text(int err) {
    return std::error_code(err, std::generic_category()).message();
}

}  // namespace

WriteError::WriteError(fs::path path, std::string reason)
    : std::runtime_error(fmt::format("{}: {}", path.string(), reason)), path_(std::move(path)),
      reason_(std::move(reason)) {}

AtomicFile::AtomicFile(fs::path destination) : destination_(std::move(destination)) {
    const fs::path dir = destination_.has_parent_path() ? destination_.parent_path() : fs::path(".");
    // O_EXCL with a name nobody else picks; mode 0666 so the umask, not
    // mkstemp's 0600, decides who can read the finished file.
    static std::atomic<unsigned> counter{0};
    std::random_device entropy;
    int last_errno = 0;
    for (int attempt = 0; attempt < 16; ++attempt) {
        const auto name = fmt::format(".{}.{}-{}-{:08x}.tmp", destination_.filename().string(), ::getpid(),
                                      counter.fetch_add(1), entropy());
        fs::path candidate = dir / name;
        const int fd = ::open(candidate.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0) {
            fd_ = fd;
            temp_ = std::move(candidate);
            return;
        }
        last_errno = errno;
        if (last_errno != EEXIST) break;
    }
    throw WriteError(destination_, fmt::format("cannot create a temporary file in '{}' to write it: {}",
                                               dir.string(), errno_text(last_errno)));
}

AtomicFile::~AtomicFile() {
    close_fd();
    if (!committed_ && !temp_.empty()) {
        std::error_code ignored;
        fs::remove(temp_, ignored);
    }
}

int AtomicFile::release_fd() noexcept {
    return std::exchange(fd_, -1);
}

void AtomicFile::close_fd() noexcept {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
}

void AtomicFile::commit() {
    close_fd();
    // fsync before rename: after a crash the destination holds either the old
    // file or the complete new one.
    const int fd = ::open(temp_.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0 || ::fsync(fd) != 0) {
        const int err = errno;
        if (fd >= 0) ::close(fd);
        throw WriteError(destination_,
                         fmt::format("cannot flush the temporary file '{}': {}", temp_.string(), errno_text(err)));
    }
    ::close(fd);
    std::error_code ec;
    fs::rename(temp_, destination_, ec);
    if (ec) throw WriteError(destination_, fmt::format("cannot move the finished file into place: {}", ec.message()));
    committed_ = true;
}

void write_file_atomically(const fs::path& file, std::string_view bytes) {
    AtomicFile out(file);
    const int fd = out.release_fd();
    std::size_t done = 0;
    int err = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            err = errno;
            break;
        }
        done += static_cast<std::size_t>(n);
    }
    if (::close(fd) != 0 && err == 0) err = errno;
    if (err != 0) throw WriteError(file, fmt::format("cannot be written: {}", errno_text(err)));
    out.commit();
}

}  // namespace atonlab::files
