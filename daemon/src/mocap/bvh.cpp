// bvh.cpp -- Biovision Hierarchy reader.
//
// The hierarchy is read token by token (line numbers kept for messages), the
// motion section line by line, so a wrong value count is reported on its line.
#include "ictus/mocap/bvh.hpp"

#include "ictus/base/enum_names.hpp"
#include "ictus/mocap/capture_bounds.hpp"
#include "text_lines.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

namespace ictus
{

namespace
{

using detail::quote;

constexpr std::size_t kMaxFileBytes = std::size_t{512} << 20; // 512 MiB
constexpr int kMaxJoints = 10000;
constexpr long kMaxJointsPerChannel = 4;
constexpr int kMaxDepth = 500; // nesting; guards the recursion
// What the format can hold at all; the physical bounds of a capture are
// narrower (capture_bounds.hpp) and may be accepted with a warning.
constexpr double kMinFrameTimeS = 1e-5; // 100 kHz
constexpr double kMaxFrameTimeS = 60.0;
// Larger values are absurd for lengths or angles and could overflow in sums.
constexpr double kMaxMagnitude = 1e9;

// Walks the tokens of the hierarchy section, line by line.
class Cursor
{
  public:
    Cursor(const std::vector<std::string> &lines, const std::string &source)
        : lines_(lines), source_(source)
    {
    }

    // The next token, or throws "expected <what>, got end of file".
    std::string next(const std::string &what)
    {
        fill();
        if (line_ >= lines_.size())
            throw MocapError(source_, static_cast<int>(lines_.size()),
                             "expected " + what + ", got end of file");
        token_line_ = static_cast<int>(line_) + 1;
        return tokens_[index_++];
    }

    const std::string *peek()
    {
        fill();
        return line_ >= lines_.size() ? nullptr : &tokens_[index_];
    }

    void expect(const std::string &word)
    {
        const std::string got = next("'" + word + "'");
        if (got != word)
            fail("'" + word + "'", got);
    }

    double number(const std::string &what)
    {
        const std::string token = next(what);
        double value = 0.0;
        if (!detail::parse_double(token, value) || !std::isfinite(value) ||
            std::fabs(value) > kMaxMagnitude)
            fail(what + " (a finite number, |x| <= 1e9)", token);
        return value;
    }

    // The rest of the current token's line, up to (not including) `stop`.
    std::vector<std::string> rest_of_line(const std::string &stop)
    {
        std::vector<std::string> rest;
        if (line_ >= lines_.size() || static_cast<int>(line_) + 1 != token_line_)
            return rest;
        while (index_ < tokens_.size() && tokens_[index_] != stop)
            rest.push_back(tokens_[index_++]);
        return rest;
    }

    [[noreturn]] void fail(const std::string &expected, const std::string &got,
                           const std::string &note = "") const
    {
        throw MocapError(source_, token_line_,
                         "expected " + expected + ", got " + quote(got) + note);
    }

    int token_line() const { return token_line_; }
    // Index of the first line after the last token taken.
    std::size_t line_after_token() const { return static_cast<std::size_t>(token_line_); }

  private:
    void fill()
    {
        while (line_ < lines_.size() && index_ >= tokens_.size()) {
            if (loaded_)
                ++line_;
            if (line_ >= lines_.size())
                break;
            tokens_ = detail::split_blanks(lines_[line_]);
            index_ = 0;
            loaded_ = true;
        }
    }

    const std::vector<std::string> &lines_;
    const std::string &source_;
    std::size_t line_ = 0;
    bool loaded_ = false;
    std::vector<std::string> tokens_;
    std::size_t index_ = 0;
    int token_line_ = 0;
};

std::string number_text(double value)
{
    std::ostringstream text;
    text << value;
    return text.str();
}

const EnumNames<6> kChannelNames = {"Xposition", "Yposition", "Zposition",
                                    "Xrotation", "Yrotation", "Zrotation"};

bool channel_from_name(const std::string &name, BvhChannel &channel)
{
    return enum_from_name(kChannelNames, name, channel);
}

bool is_position(BvhChannel c)
{
    return c == BvhChannel::Xposition || c == BvhChannel::Yposition || c == BvhChannel::Zposition;
}

int channel_axis(BvhChannel c)
{
    switch (c) {
    case BvhChannel::Xposition:
    case BvhChannel::Xrotation:
        return 0;
    case BvhChannel::Yposition:
    case BvhChannel::Yrotation:
        return 1;
    default:
        return 2;
    }
}

class BvhParser
{
  public:
    BvhParser(const std::vector<std::string> &lines, const std::string &source,
              const BvhOptions &options, MocapWarnings *warnings)
        : lines_(lines), source_(source), options_(options), warnings_(warnings),
          cursor_(lines, source)
    {
    }

    BvhFile parse()
    {
        if (!std::isfinite(options_.scale) || options_.scale <= 0.0)
            throw MocapError(source_, 0,
                             "expected BvhOptions::scale finite and > 0, got " +
                                 std::to_string(options_.scale));
        bvh_.skeleton.source = source_;
        cursor_.expect("HIERARCHY");
        cursor_.expect("ROOT");
        parse_joint(-1, 0);
        const std::string after = cursor_.next("MOTION");
        if (after != "MOTION")
            cursor_.fail("MOTION (one ROOT hierarchy, braces balanced)", after);
        if (bvh_.channel_count == 0)
            throw MocapError(source_, cursor_.token_line(),
                             "expected at least one channel in the hierarchy, got none");
        // Every joint costs a rotation per frame, channels or not: a
        // hierarchy of End Sites and channel-less joints would make a small
        // file ask for gigabytes (1300 End Sites under one channel, 14000
        // frames: 740 MB, 35 s). A captured body moves its joints: at most
        // kMaxJointsPerChannel joints per channel (CMU: 38 joints, 62 channels).
        const auto joints = static_cast<long>(bvh_.skeleton.joints.size());
        if (joints > kMaxJointsPerChannel * static_cast<long>(bvh_.channel_count))
            throw MocapError(source_, cursor_.token_line(),
                             "expected at most " + std::to_string(kMaxJointsPerChannel) +
                                 " joints (End Sites included) per channel, got " +
                                 std::to_string(joints) + " joints for " +
                                 std::to_string(bvh_.channel_count) +
                                 " channels (a hierarchy that does not move)");
        const long declared = parse_frames();
        parse_frame_time();
        const double duration_s = static_cast<double>(declared - 1) * bvh_.frame_time_s;
        if (duration_s > kMaxCaptureDuration_s)
            out_of_bounds(frames_line_, "duration",
                          "expected a capture of at most " + number_text(kMaxCaptureDuration_s) +
                              " s (3 h), got Frames: " + std::to_string(declared) +
                              " at Frame Time " + number_text(bvh_.frame_time_s) +
                              " s = " + number_text(duration_s) + " s");
        parse_motion(declared);
        return std::move(bvh_);
    }

  private:
    void parse_joint(int parent, int depth)
    {
        const int keyword_line = cursor_.token_line();
        if (depth > kMaxDepth)
            throw MocapError(source_, keyword_line,
                             "expected a hierarchy at most " + std::to_string(kMaxDepth) +
                                 " joints deep, got deeper");
        if (static_cast<int>(bvh_.skeleton.joints.size()) >= kMaxJoints)
            throw MocapError(source_, keyword_line,
                             "expected at most " + std::to_string(kMaxJoints) +
                                 " joints, got more");
        std::string name;
        for (const std::string &part : cursor_.rest_of_line("{"))
            name += (name.empty() ? "" : " ") + part;
        if (name.empty())
            throw MocapError(source_, keyword_line, "expected a joint name, got end of line");
        cursor_.expect("{");
        SkeletonJoint joint;
        joint.name = name;
        joint.parent = parent;
        joint.offset_m = parse_offset(name, joint.offset_line);
        const int index = static_cast<int>(bvh_.skeleton.joints.size());
        bvh_.skeleton.joints.push_back(joint);
        bvh_.channels.emplace_back();
        const std::string *ahead = cursor_.peek();
        if (ahead && *ahead == "CHANNELS")
            parse_channels(index, parent);
        for (;;) {
            const std::string token = cursor_.next("JOINT, End Site or '}'");
            if (token == "JOINT") {
                parse_joint(index, depth + 1);
            } else if (token == "End") {
                const std::string site = cursor_.next("Site");
                if (site != "Site" && site != "site")
                    cursor_.fail("Site", site);
                parse_end_site(index);
            } else if (token == "}") {
                return;
            } else {
                cursor_.fail("JOINT, End Site or '}' (in joint " + name + ")", token);
            }
        }
    }

    // OFFSET x y z of joint `name`, scaled to metres; `line` gets its line.
    Eigen::Vector3d parse_offset(const std::string &name, int &line)
    {
        cursor_.expect("OFFSET");
        line = cursor_.token_line();
        Eigen::Vector3d offset;
        for (int k = 0; k < 3; ++k) {
            offset[k] = cursor_.number("an OFFSET coordinate") * options_.scale;
            if (std::fabs(offset[k]) > kMaxCoordinate_m)
                out_of_bounds(
                    cursor_.token_line(), "offset",
                    "expected |OFFSET coordinate| * scale <= " + number_text(kMaxCoordinate_m) +
                        " m (joint " + name + ", scale " + number_text(options_.scale) + "), got " +
                        number_text(offset[k] / options_.scale) + " = " + number_text(offset[k]) +
                        " m");
        }
        return offset;
    }

    void parse_channels(int index, int parent)
    {
        cursor_.expect("CHANNELS");
        const std::string count_token = cursor_.next("a channel count");
        double count = 0.0;
        if (!detail::parse_double(count_token, count) || count != std::floor(count) ||
            count < 0.0 || count > 6.0)
            cursor_.fail("a channel count 0..6", count_token);
        std::vector<BvhChannel> &channels = bvh_.channels[static_cast<std::size_t>(index)];
        for (int c = 0; c < static_cast<int>(count); ++c) {
            const std::string channel_name = cursor_.next("a channel name");
            BvhChannel channel;
            if (!channel_from_name(channel_name, channel))
                cursor_.fail("a channel name (Xposition Yposition Zposition Xrotation "
                             "Yrotation Zrotation)",
                             channel_name);
            for (BvhChannel seen : channels)
                if (seen == channel)
                    cursor_.fail("each channel once per joint", channel_name);
            channels.push_back(channel);
            if (is_position(channel) && parent >= 0 && !has_joint_translation_) {
                has_joint_translation_ = true;
                first_translation_line_ = cursor_.token_line();
                first_translation_joint_ =
                    bvh_.skeleton.joints[static_cast<std::size_t>(index)].name;
            }
        }
        bvh_.channel_count += static_cast<int>(count);
    }

    void parse_end_site(int parent)
    {
        cursor_.expect("{");
        SkeletonJoint site;
        site.name = bvh_.skeleton.joints[static_cast<std::size_t>(parent)].name + "_End";
        site.parent = parent;
        site.end_site = true;
        site.offset_m = parse_offset(site.name, site.offset_line);
        cursor_.expect("}");
        if (static_cast<int>(bvh_.skeleton.joints.size()) >= kMaxJoints)
            throw MocapError(source_, cursor_.token_line(),
                             "expected at most " + std::to_string(kMaxJoints) +
                                 " joints, got more");
        bvh_.skeleton.joints.push_back(site);
        bvh_.channels.emplace_back();
    }

    // The value after `label` ("Frames:"), a token of its own or joined to
    // the label ("Frames:N"); `what` names the value when it is missing.
    std::string labelled_value(const std::string &label, const char *what)
    {
        const std::string token = cursor_.next(label);
        if (token == label)
            return cursor_.next(what);
        if (token.rfind(label, 0) != 0)
            cursor_.fail(label, token);
        return token.substr(label.size());
    }

    // "Frames: N" (also "Frames:N").
    long parse_frames()
    {
        const std::string value_token = labelled_value("Frames:", "a frame count");
        frames_line_ = cursor_.token_line();
        double frames = 0.0;
        const std::string range = "[1, " + std::to_string(options_.max_frames) + "]";
        if (!detail::parse_double(value_token, frames) || !std::isfinite(frames) ||
            frames != std::floor(frames) || frames < 1.0 ||
            frames > static_cast<double>(options_.max_frames))
            cursor_.fail("a whole frame count in " + range, value_token);
        return static_cast<long>(frames);
    }

    // "Frame Time: T" (s). A rate that the printed T matches to its last
    // printed digit is snapped to the integer (".0083333" -> 120 Hz).
    void parse_frame_time()
    {
        const std::string frame = cursor_.next("Frame Time:");
        if (frame != "Frame")
            cursor_.fail("Frame Time:", frame);
        const std::string value_token = labelled_value("Time:", "a frame time");
        double frame_time = 0.0;
        const bool number = detail::parse_double(value_token, frame_time) &&
                            std::isfinite(frame_time) && frame_time > 0.0;
        // A rate typed where the interval goes (`Frame Time: 30`, a capture's 2 Hz
        // to 2 kHz) is said as such.
        const double interval_if_rate = number ? 1.0 / frame_time : 0.0;
        const std::string hint =
            interval_if_rate >= kMinSampleInterval_s && interval_if_rate <= kMaxSampleInterval_s
                ? " (a rate? Frame Time is seconds per frame: " + value_token + " Hz is " +
                      number_text(interval_if_rate) + " s)"
                : "";
        if (!number || frame_time < kMinFrameTimeS || frame_time > kMaxFrameTimeS)
            cursor_.fail("a frame time in [1e-05, 60] s", value_token, hint);
        if (frame_time < kMinSampleInterval_s || frame_time > kMaxSampleInterval_s)
            out_of_bounds(cursor_.token_line(), "frame time",
                          "expected a frame time in [" + number_text(kMinSampleInterval_s) + ", " +
                              number_text(kMaxSampleInterval_s) +
                              "] s (a capture at 2 Hz to 2 kHz), got " + quote(value_token) + hint);
        const std::vector<std::string> extra = cursor_.rest_of_line("");
        if (!extra.empty())
            cursor_.fail("end of line after the frame time", extra.front());
        double rate = 1.0 / frame_time;
        const std::size_t dot = value_token.find('.');
        if (dot != std::string::npos && value_token.find_first_of("eE") == std::string::npos) {
            const int decimals = static_cast<int>(value_token.size() - dot - 1);
            const double half_last_digit = 0.5 * std::pow(10.0, -decimals);
            const double whole = std::round(rate);
            // Both: within the printed precision, and a change of the rate below
            // 1e-4 (so that "0.3" does not become 3 Hz).
            if (whole >= 1.0 && std::fabs(1.0 / whole - frame_time) <= half_last_digit * 1.000001 &&
                std::fabs(rate - whole) <= 1e-4 * whole)
                rate = whole;
        }
        bvh_.frame_time_s = 1.0 / rate;
        bvh_.motion.frame_rate_hz = rate;
        frame_time_line_ = cursor_.token_line();
    }

    void parse_motion(long declared)
    {
        const std::size_t joint_count = bvh_.skeleton.joints.size();
        const auto channel_count = static_cast<std::size_t>(bvh_.channel_count);
        if (options_.skip_frames < 0 || options_.skip_frames >= declared)
            throw MocapError(source_, frame_time_line_ - 1,
                             "expected the frames skipped at the start (--skip-frames, "
                             "BvhOptions::skip_frames) in [0, " +
                                 std::to_string(declared - 1) + "], got " +
                                 std::to_string(options_.skip_frames) + " (the file has " +
                                 std::to_string(declared) +
                                 (declared == 1 ? " frame)" : " frames)"));
        // Columns holding a position (compared with kMaxCoordinate_m).
        std::vector<bool> position_column;
        for (const auto &list : bvh_.channels)
            for (BvhChannel channel : list)
                position_column.push_back(is_position(channel));
        std::vector<double> values(channel_count);
        long read = 0;
        long extra_lines = 0;
        int first_extra_line = 0;
        for (std::size_t l = static_cast<std::size_t>(frame_time_line_); l < lines_.size(); ++l) {
            const int line_number = static_cast<int>(l) + 1;
            const std::vector<std::string> tokens = detail::split_blanks(lines_[l]);
            if (tokens.empty())
                continue;
            if (read == declared) {
                if (extra_lines++ == 0)
                    first_extra_line = line_number;
                continue;
            }
            if (tokens.size() != channel_count)
                throw MocapError(source_, line_number,
                                 "expected " + std::to_string(channel_count) +
                                     " values (one per channel) on motion line " +
                                     std::to_string(read + 1) + ", got " +
                                     std::to_string(tokens.size()));
            for (std::size_t c = 0; c < channel_count; ++c) {
                if (!detail::parse_double(tokens[c], values[c]) || !std::isfinite(values[c]) ||
                    std::fabs(values[c]) > kMaxMagnitude)
                    throw MocapError(source_, line_number,
                                     "expected a finite number (|x| <= 1e9) in column " +
                                         std::to_string(c + 1) + " (" + channel_label(c) +
                                         "), got " + quote(tokens[c]));
                if (position_column[c] && std::fabs(values[c] * options_.scale) > kMaxCoordinate_m)
                    out_of_bounds(line_number, "position",
                                  "expected |position| * scale <= " +
                                      number_text(kMaxCoordinate_m) + " m in column " +
                                      std::to_string(c + 1) + " (" + channel_label(c) + ", scale " +
                                      number_text(options_.scale) + "), got " + quote(tokens[c]) +
                                      " = " + number_text(values[c] * options_.scale) + " m");
            }
            if (read >= options_.skip_frames)
                add_frame(values, joint_count);
            ++read;
        }
        if (read < declared)
            throw MocapError(source_, static_cast<int>(lines_.size()),
                             "expected " + std::to_string(declared) +
                                 " motion lines (Frames: " + std::to_string(declared) + "), got " +
                                 std::to_string(read) + " (truncated file?)");
        if (extra_lines > 0 && warnings_)
            warnings_->push_back(
                source_ + ":" + std::to_string(first_extra_line) + ": ignored " +
                std::to_string(extra_lines) +
                " motion line(s) beyond the declared Frames: " + std::to_string(declared));
        if (has_joint_translation_ && warnings_)
            warnings_->push_back(
                source_ + ":" + std::to_string(first_translation_line_) + ": joint '" +
                first_translation_joint_ +
                "' has position channels (the first of the non-root joints that have them): the "
                "character (ictusd --mocap) plays the joints' rotations on the OFFSETs and "
                "ignores them (bvh_forward_kinematics reads them, forward_kinematics(Skeleton, "
                "Motion) does not)");
    }

    // A value out of the physical bounds of a capture (capture_bounds.hpp):
    // refused, or read with a warning (the first of each kind) when accepted.
    void out_of_bounds(int line, const std::string &kind, const std::string &message)
    {
        bounds_.out_of_bounds(line, kind, message);
    }

    std::string channel_label(std::size_t column) const
    {
        std::size_t c = column;
        for (std::size_t j = 0; j < bvh_.channels.size(); ++j) {
            if (c < bvh_.channels[j].size())
                return bvh_.skeleton.joints[j].name + " " + to_string(bvh_.channels[j][c]);
            c -= bvh_.channels[j].size();
        }
        return "?";
    }

    void add_frame(const std::vector<double> &values, std::size_t joint_count)
    {
        constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
        std::vector<Eigen::Quaterniond> rotation(joint_count, Eigen::Quaterniond::Identity());
        std::vector<Eigen::Vector3d> translation;
        if (has_joint_translation_)
            translation.resize(joint_count);
        Eigen::Vector3d root_position = bvh_.skeleton.joints[0].offset_m;
        std::size_t column = 0;
        for (std::size_t j = 0; j < joint_count; ++j) {
            Eigen::Vector3d moved = Eigen::Vector3d::Zero();
            Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
            for (BvhChannel channel : bvh_.channels[j]) {
                const double value = values[column++];
                if (is_position(channel))
                    moved[channel_axis(channel)] = value * options_.scale;
                else // intrinsic: each later channel rotates about the already-rotated axes
                    q = q * axis_rotation(channel_axis(channel), value * kDegToRad);
            }
            rotation[j] = q.normalized();
            const Eigen::Vector3d placed = bvh_.skeleton.joints[j].offset_m + moved;
            if (j == 0)
                root_position = placed;
            if (has_joint_translation_)
                translation[j] = placed;
        }
        bvh_.motion.root_position_m.push_back(root_position);
        bvh_.motion.local_rotation.push_back(std::move(rotation));
        if (has_joint_translation_)
            bvh_.joint_translation_m.push_back(std::move(translation));
    }

    const std::vector<std::string> &lines_;
    const std::string &source_;
    const BvhOptions &options_;
    MocapWarnings *warnings_;
    Cursor cursor_;
    BvhFile bvh_;
    bool has_joint_translation_ = false;
    int first_translation_line_ = 0;      // the first non-root position channel's line
    std::string first_translation_joint_; // and its joint
    int frame_time_line_ = 0;
    int frames_line_ = 0;
    BoundsReport bounds_{source_, options_.accept_out_of_bounds, warnings_};
};

// A body whose hips-to-head line in the first frame is further than
// kUprightMaxDeg from +y (BVH is read y up): most likely a z-up capture, which
// the character would play lying down. Said, not refused (a performer may lie).
constexpr double kUprightMaxDeg = 60.0;

void warn_if_not_upright(const BvhFile &bvh, const std::string &source, MocapWarnings *warnings)
{
    const int hips = bvh.skeleton.find("Hips"), head = bvh.skeleton.find("Head");
    if (!warnings || hips < 0 || head < 0 || bvh.motion.frames() == 0)
        return;
    const std::vector<Eigen::Vector3d> p = bvh_forward_kinematics(bvh, 0);
    const Eigen::Vector3d up =
        p[static_cast<std::size_t>(head)] - p[static_cast<std::size_t>(hips)];
    if (up.norm() < 1e-9)
        return;
    const double deg = std::acos(std::clamp(up.normalized().y(), -1.0, 1.0)) * 180.0 / M_PI;
    if (deg > kUprightMaxDeg)
        warnings->push_back(source + ": the body's hips-to-head line is " +
                            std::to_string(static_cast<int>(std::lround(deg))) +
                            " degrees from up (+y) in the first frame: a z-up capture? BVH is "
                            "read y up: the character would play it lying (docs/mocap.md)");
}

} // namespace

int BvhFile::channelled_joints() const
{
    int count = 0;
    for (const auto &list : channels)
        count += list.empty() ? 0 : 1;
    return count;
}

const char *to_string(BvhChannel channel)
{
    return enum_name(kChannelNames, channel, "?");
}

BvhFile parse_bvh(std::istream &in, const std::string &source_name, const BvhOptions &options,
                  MocapWarnings *warnings)
{
    const std::vector<std::string> lines = detail::read_lines(in, source_name, kMaxFileBytes);
    BvhParser parser(lines, source_name, options, warnings);
    BvhFile bvh = parser.parse();
    warn_if_not_upright(bvh, source_name, warnings);
    return bvh;
}

BvhFile read_bvh(const std::string &path, const BvhOptions &options, MocapWarnings *warnings)
{
    std::ifstream in = detail::open_capture(path, "BVH");
    return parse_bvh(in, path, options, warnings);
}

std::vector<Eigen::Vector3d> bvh_forward_kinematics(const BvhFile &bvh, int frame)
{
    if (bvh.joint_translation_m.empty())
        return forward_kinematics(bvh.skeleton, bvh.motion, frame);
    const std::vector<Eigen::Quaterniond> world =
        world_rotations(bvh.skeleton, bvh.motion, frame); // checks frame and sizes
    const auto &translation = bvh.joint_translation_m[static_cast<std::size_t>(frame)];
    std::vector<Eigen::Vector3d> position(bvh.skeleton.joints.size());
    for (std::size_t j = 0; j < bvh.skeleton.joints.size(); ++j) {
        const int parent = bvh.skeleton.joints[j].parent;
        position[j] =
            parent < 0 ? translation[j]
                       : Eigen::Vector3d(position[static_cast<std::size_t>(parent)] +
                                         world[static_cast<std::size_t>(parent)] * translation[j]);
    }
    return position;
}

} // namespace ictus
