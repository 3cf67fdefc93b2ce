// A CSV log that holds several recording sessions one after another (time
// restarting, as when logs are concatenated): the longest piece whose time
// increases, so a fit can use it instead of rejecting the file, and a note
// saying what was left out.

#ifndef IMUSYSID_SRC_TOOLS_SESSIONS_H_
#define IMUSYSID_SRC_TOOLS_SESSIONS_H_

#include <string>
#include <string_view>

namespace imusysid {

struct OrderedPiece {
  // The CSV text to parse: the lines before the header, the header and the
  // rows of the longest piece whose time increases strictly. Equal to the
  // input when time never goes back (or the text is not a CSV log this
  // function understands: the reader then reports what is wrong).
  std::string text;
  // Empty when the whole file is one ordered piece; else one sentence for
  // the user naming the pieces and the one used.
  std::string note;
};

// `name` names the file in the note.
OrderedPiece LongestOrderedCsvPiece(std::string_view text,
                                    const std::string& name);

}  // namespace imusysid

#endif  // IMUSYSID_SRC_TOOLS_SESSIONS_H_
