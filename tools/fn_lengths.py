#!/usr/bin/env python3
"""The longest functions under a folder (issue #31's "no cli/ function over 120 lines").

    python3 tools/fn_lengths.py src/cli [N]    # N longest, default 10: lines, file, name, first line
"""
import re,sys,os
res=[]
for root,_,fs in os.walk(sys.argv[1]):
  for f in fs:
    if not f.endswith('.rs'): continue
    p=os.path.join(root,f); L=open(p).read().split('\n')
    i=0
    while i<len(L):
      m=re.match(r'\s*(pub(\([^)]*\))?\s+)?(async\s+)?fn\s+(\w+)',L[i])
      if m:
        ind=len(L[i])-len(L[i].lstrip()); j=i
        # find start brace
        while j<len(L) and '{' not in L[j] and not L[j].rstrip().endswith(';'): j+=1
        if j<len(L) and L[j].rstrip().endswith(';'): i+=1; continue
        k=j+1
        while k<len(L) and not (L[k].startswith(' '*ind+'}') and len(L[k])-len(L[k].lstrip())==ind): k+=1
        res.append((k-i+1,p,m.group(4),i+1))
      i+=1
res.sort(reverse=True)
for r in res[:int(sys.argv[2]) if len(sys.argv)>2 else 10]: print(*r)
