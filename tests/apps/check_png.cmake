# Checks that a file is a PNG of a given size: the signature, then the IHDR
# chunk with width and height.
#
#   cmake -DPNG=<path> -DWIDTH=<w> -DHEIGHT=<h> -P check_png.cmake

if(NOT EXISTS "${PNG}")
  message(FATAL_ERROR "${PNG} was not written")
endif()
file(READ "${PNG}" head LIMIT 24 HEX)
string(SUBSTRING "${head}" 0 16 signature)
string(SUBSTRING "${head}" 24 8 chunk)
string(SUBSTRING "${head}" 32 8 width_hex)
string(SUBSTRING "${head}" 40 8 height_hex)
math(EXPR width "0x${width_hex}")
math(EXPR height "0x${height_hex}")
if(NOT signature STREQUAL "89504e470d0a1a0a")
  message(FATAL_ERROR "${PNG}: no PNG signature (${signature})")
endif()
if(NOT chunk STREQUAL "49484452")
  message(FATAL_ERROR "${PNG}: the first chunk is not IHDR")
endif()
if(NOT width EQUAL WIDTH OR NOT height EQUAL HEIGHT)
  message(FATAL_ERROR "${PNG}: ${width}x${height}, expected ${WIDTH}x${HEIGHT}")
endif()
