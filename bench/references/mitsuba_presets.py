import mitsuba as mi
mi.set_variant('scalar_rgb')
names = ['a-C','Ag','Al','AlAs','AlSb','Au','Be','Cr','CsI','Cu','Cu2O','CuO','d-C','Hg','HgTe','Ir','K','Li','MgO','Mo','Na_palik','Nb','Ni_palik','Rh','Se','SiC','SnTe','Ta','Te','ThF4','TiC','TiN','TiO2','VC','V_palik','VN','W','none']
for n in names:
    try:
        b = mi.load_dict({'type':'conductor','material':n})
        p = mi.traverse(b)
        eta = p['eta.value'] if 'eta.value' in p.keys() else None
        k = p['k.value'] if 'k.value' in p.keys() else None
        print(n, list(p.keys()), eta, k)
    except Exception as e:
        print(n, 'ERR', e)
