# doxygen-filter.sed - turns the public headers' plain C comments into Doxygen comments
# as Doxygen reads them (INPUT_FILTER), so the headers need no Doxygen markup.
#   line 1 "/* vwalls/x.h - what it is"  ->  the file's documentation
#   "/* ..." opening a line              ->  "/** ...", documents what follows
#   "code; /* ..."                       ->  "code; /**< ...", documents that member
1s|^/\* vwalls/[A-Za-z_]*\.h - |/** \\file\n * |
1!s|^\([[:space:]]*\)/\* |\1/** |
s|^\([[:space:]]*[^[:space:]/*].*\)/\* |\1/**< |
# "#word" in a comment is an explicit link for Doxygen; escape it unless it is "##" (token
# pasting) or a preprocessor directive opening the line.
s/\(^\|[^#]\)#\([A-Za-z_]\)/\1\\#\2/g
s/^\([[:space:]]*\)\\#\(define\|include\|if\|ifdef\|ifndef\|endif\|else\|elif\|undef\|pragma\|error\)\>/\1#\2/
