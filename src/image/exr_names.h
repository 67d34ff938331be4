#pragma once
// Private to msm_image: what its EXR writer (exr_encode.cpp) and reader (io.cpp) agree on.
namespace msm::image {
// A string vector of the image's channel names in its own order (EXR stores channels sorted by
// name); the reader restores that order when the attribute names the file's channels exactly.
inline constexpr const char* channel_order_attribute = "msmChannelOrder";
} // namespace msm::image
