// Writes a small real JPEG (OpenCV's encoder) for the bag generator: make_test_bags.py needs
// CompressedImage payloads and Debian's ROS Python packages bring no image encoder.
#include <iostream>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: write_test_jpeg OUT.jpg\n";
    return 2;
  }
  cv::Mat img(24, 40, CV_8UC3);
  for (int r = 0; r < img.rows; ++r)
    for (int c = 0; c < img.cols; ++c) img.at<cv::Vec3b>(r, c) = cv::Vec3b(uchar(r * 10), uchar(c * 6), 128);
  return cv::imwrite(argv[1], img) ? 0 : 1;
}
