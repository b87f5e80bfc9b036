// The protocols library; see include/atonlab/protocols/.
namespace atonlab::protocols {
int library_version() {
    return 1;
}
}  // namespace atonlab::protocols
