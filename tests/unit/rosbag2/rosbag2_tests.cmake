# Included from tests/CMakeLists.txt: paths are relative to tests/.
