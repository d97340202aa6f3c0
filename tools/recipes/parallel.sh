# GNU parallel: 6 jobs of 30 frames each (the walk is 180 frames at 30 fps) into one folder
seq 0 5 | parallel 'ocular video --scene walk --eye myopia -o frames/ --frames $(({}*30))..$(( ({}+1)*30 ))'
