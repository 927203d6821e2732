# Included from plugins/CMakeLists.txt: paths are relative to plugins/.
